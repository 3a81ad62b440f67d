//! The host ↔ firmware link: frames, messages and the stream accumulator (see `docs/spec/link.md`).
