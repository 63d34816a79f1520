//! `GMap::validate` (every law, including id uniqueness) on Kuhn cubes; throughput in darts.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

mod common;

fn validate(c: &mut Criterion) {
    let mut group = c.benchmark_group("validate");
    for k in common::SIZES {
        let (_, _, map) = common::cube(k);
        group.throughput(Throughput::Elements(map.dart_count() as u64));
        group.bench_with_input(BenchmarkId::new("validate", k), &map, |b, map| {
            b.iter(|| std::hint::black_box(map).validate().expect("valid"))
        });
    }
    group.finish();
}

criterion_group! { name = benches; config = common::config(); targets = validate }
criterion_main!(benches);
