//! Link throughput: encode + frame + COBS, and accumulate + verify + parse, of a batch of 32
//! MPU-9250 register images (22 bytes); prints the link-efficiency table of every image length
//! first.
//!
//! `cargo bench -p margemu-protocol --bench link`

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use margemu_protocol::chip::ChipModel;
use margemu_protocol::link::{
    image_batch_efficiency, image_batch_wire_len, max_images_per_batch, Accumulator, Encoder,
    FeedResult, FrameRepr, Image, ImageBatch, Message, MAX_WIRE_LEN,
};

const BATCH: usize = 32;
const IMAGE_LEN: usize = ChipModel::Mpu9250.image_len();

fn images() -> Vec<Image> {
    // Register-like content: small values with zero bytes, so COBS does real work.
    (0..BATCH)
        .map(|i| {
            let bytes: [u8; IMAGE_LEN] = core::array::from_fn(|k| ((i * 31 + k * 7) % 251) as u8);
            Image::from(bytes)
        })
        .collect()
}

fn print_efficiency_table() {
    println!(
        "image batches, worst case (COBS ⌈n/254⌉, two 0x00, 6 B header, 8 B index, 1 B image \
         length, 4 B CRC):"
    );
    println!(
        "{:>6} {:>6} {:>11} {:>10} {:>11}",
        "length", "images", "image bytes", "wire bytes", "efficiency"
    );
    for len in [14, 22, 32] {
        for n in [1, 8, 16, 32, 64]
            .into_iter()
            .filter(|&n| n <= max_images_per_batch(len))
        {
            let (payload, wire) = (n * len, image_batch_wire_len(n, len));
            let e = 100.0 * image_batch_efficiency(n, len);
            println!("{len:>6} {n:>6} {payload:>11} {wire:>10} {e:>10.1} %");
        }
    }
}

fn bench(c: &mut Criterion) {
    print_efficiency_table();
    let images = images();
    let message = Message::Images(ImageBatch::new(1 << 20, &images));
    let mut encoder = Encoder::new();
    let mut wire = [0u8; MAX_WIRE_LEN];
    let n = encoder.encode(&message, &mut wire).unwrap();

    let mut group = c.benchmark_group("image_batch_32");
    group.throughput(Throughput::Bytes(n as u64));
    group.bench_function("encode", |b| {
        let mut out = [0u8; MAX_WIRE_LEN];
        b.iter(|| encoder.encode(black_box(&message), &mut out).unwrap())
    });
    group.bench_function("accumulate_decode", |b| {
        let mut acc = Accumulator::new();
        b.iter(|| {
            let FeedResult::Success { frame, .. } = acc.feed(black_box(&wire[..n])) else {
                unreachable!()
            };
            let repr = FrameRepr::parse(&frame).unwrap();
            let Message::Images(batch) = repr.message else {
                unreachable!()
            };
            // Touch every image, as the firmware would when copying it into its buffer.
            batch
                .images
                .iter()
                .fold(0u8, |x, img| x ^ img[IMAGE_LEN - 1])
        })
    });
    group.bench_function("accumulate_decode_bytewise", |b| {
        let mut acc = Accumulator::new();
        b.iter(|| {
            let mut frames = 0;
            for byte in wire[..n].chunks(1) {
                if let FeedResult::Success { frame, .. } = acc.feed(black_box(byte)) {
                    frames += FrameRepr::parse(&frame).is_ok() as u32;
                }
            }
            frames
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
