//! margemu host library.
