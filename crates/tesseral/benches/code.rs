//! Tesseral addressing and arithmetic over arrays of 1M codes (issue 2, section 6).
//!
//! Targets: encode <= 3 ns/code, decode <= 3 ns/code, add <= 1 ns/code. Every group
//! holds the baselines measured in the same run: magic bits vs BMI2 for encode and
//! decode; word-parallel add vs decode-add-encode vs the papers' digit-table adder.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::hint::black_box;
use tesseral::code::batch::{decode_slice_with, encode_slice_with};
use tesseral::code::digits::add_by_table;
use tesseral::code::{Backend, CodeWord, Space};

const N: usize = 1 << 20;
const SEED: u64 = 0x7e55_e4a1;

fn points32() -> Vec<[u32; 3]> {
    let mut rng = Pcg64::seed_from_u64(SEED);
    (0..N)
        .map(|_| [0; 3].map(|_: u32| rng.random::<u32>() & 0x1f_ffff))
        .collect()
}

fn points64() -> Vec<[u64; 3]> {
    let mut rng = Pcg64::seed_from_u64(SEED + 1);
    (0..N)
        .map(|_| [0; 3].map(|_: u64| rng.random::<u64>() & ((1 << 42) - 1)))
        .collect()
}

fn backends() -> Vec<Backend> {
    [Backend::MagicBits, Backend::Bmi2]
        .into_iter()
        .filter(|b| b.is_available())
        .collect()
}

fn bench_encode(c: &mut Criterion) {
    let p32 = points32();
    let p64 = points64();
    let mut out64 = vec![0u64; N];
    let mut out128 = vec![0u128; N];
    let mut g = c.benchmark_group("encode_1M");
    g.throughput(Throughput::Elements(N as u64));
    for b in backends() {
        g.bench_function(BenchmarkId::new("u64", format!("{b:?}")), |bench| {
            bench.iter(|| {
                encode_slice_with(b, black_box(&p32), &mut out64).unwrap();
                black_box(&out64);
            })
        });
        g.bench_function(BenchmarkId::new("u128", format!("{b:?}")), |bench| {
            bench.iter(|| {
                encode_slice_with(b, black_box(&p64), &mut out128).unwrap();
                black_box(&out128);
            })
        });
    }
    g.finish();
}

fn bench_decode(c: &mut Criterion) {
    let codes64: Vec<u64> = points32()
        .iter()
        .map(|&[x, y, z]| <u64 as CodeWord>::encode(x, y, z))
        .collect();
    let codes128: Vec<u128> = points64()
        .iter()
        .map(|&[x, y, z]| <u128 as CodeWord>::encode(x, y, z))
        .collect();
    let mut out32 = vec![[0u32; 3]; N];
    let mut out64 = vec![[0u64; 3]; N];
    let mut g = c.benchmark_group("decode_1M");
    g.throughput(Throughput::Elements(N as u64));
    for b in backends() {
        g.bench_function(BenchmarkId::new("u64", format!("{b:?}")), |bench| {
            bench.iter(|| {
                decode_slice_with(b, black_box(&codes64), &mut out32).unwrap();
                black_box(&out32);
            })
        });
        g.bench_function(BenchmarkId::new("u128", format!("{b:?}")), |bench| {
            bench.iter(|| {
                decode_slice_with(b, black_box(&codes128), &mut out64).unwrap();
                black_box(&out64);
            })
        });
    }
    g.finish();
}

fn bench_add(c: &mut Criterion) {
    let mut rng = Pcg64::seed_from_u64(SEED + 2);
    let s = Space::<u64>::full();
    let a: Vec<u64> = (0..N).map(|_| rng.random::<u64>() & s.mask()).collect();
    let b: Vec<u64> = (0..N).map(|_| rng.random::<u64>() & s.mask()).collect();
    let mut out = vec![0u64; N];
    let mut g = c.benchmark_group("add_1M");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("tesseral_add", |bench| {
        bench.iter(|| {
            let s = black_box(s);
            for ((o, &x), &y) in out.iter_mut().zip(&a).zip(&b) {
                *o = s.add(x, y);
            }
            black_box(&out);
        })
    });
    g.bench_function("add_slices", |bench| {
        bench.iter(|| {
            tesseral::code::batch::add_slices(&s, black_box(&a), black_box(&b), &mut out).unwrap();
            black_box(&out);
        })
    });
    g.bench_function("translate_in_place", |bench| {
        let by = b[0];
        bench.iter(|| {
            tesseral::code::batch::translate_slice(&s, &mut out, black_box(by));
            black_box(&out);
        })
    });
    g.bench_function("decode_add_encode", |bench| {
        bench.iter(|| {
            for ((o, &x), &y) in out.iter_mut().zip(&a).zip(&b) {
                let [ax, ay, az] = tesseral::code::decode(x);
                let [bx, by, bz] = tesseral::code::decode(y);
                *o = tesseral::code::encode(
                    ax.wrapping_add(bx),
                    ay.wrapping_add(by),
                    az.wrapping_add(bz),
                );
            }
            black_box(&out);
        })
    });
    if Backend::Bmi2.is_available() {
        let mut pa = vec![[0u32; 3]; N];
        let mut pb = vec![[0u32; 3]; N];
        g.bench_function("decode_add_encode_bmi2", |bench| {
            bench.iter(|| {
                decode_slice_with(Backend::Bmi2, &a, &mut pa).unwrap();
                decode_slice_with(Backend::Bmi2, &b, &mut pb).unwrap();
                for (p, q) in pa.iter_mut().zip(&pb) {
                    *p = [0, 1, 2].map(|k| p[k].wrapping_add(q[k]));
                }
                encode_slice_with(Backend::Bmi2, &pa, &mut out).unwrap();
                black_box(&out);
            })
        });
    }
    g.bench_function("digit_table_adder", |bench| {
        bench.iter(|| {
            for ((o, &x), &y) in out.iter_mut().zip(&a).zip(&b) {
                *o = add_by_table(x, y, 21).code;
            }
            black_box(&out);
        })
    });
    g.finish();
}

criterion_group!(benches, bench_encode, bench_decode, bench_add);
criterion_main!(benches);
