//! `GMap::<3>::from_tets` on Kuhn cubes; throughput in darts.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use topomech::GMap;

mod common;

fn build(c: &mut Criterion) {
    let mut group = c.benchmark_group("build");
    for k in common::SIZES {
        let (tets, points, map) = common::cube(k);
        group.throughput(Throughput::Elements(map.dart_count() as u64));
        group.bench_with_input(BenchmarkId::new("from_tets", k), &tets, |b, tets| {
            b.iter(|| GMap::<3>::from_tets(points, std::hint::black_box(tets)).expect("builds"))
        });
    }
    group.finish();
}

criterion_group! { name = benches; config = common::config(); targets = build }
criterion_main!(benches);
