use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn bench_encode(c: &mut Criterion) {
    let xs: Vec<[u32; 3]> = (0..1_000_000u32)
        .map(|i| {
            [
                i & 0x1f_ffff,
                i.wrapping_mul(7) & 0x1f_ffff,
                i.wrapping_mul(13) & 0x1f_ffff,
            ]
        })
        .collect();
    c.bench_function("encode_1M", |b| {
        b.iter(|| {
            xs.iter()
                .map(|&[x, y, z]| tesseral::code::encode(x, y, z))
                .fold(0, |a, c| a ^ black_box(c))
        })
    });
}

criterion_group!(benches, bench_encode);
criterion_main!(benches);
