//! `GMap::orbit` of every i-cell of a Kuhn cube (one BFS per cell); throughput in darts visited.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use topomech::AlphaMask;

mod common;

fn orbit(c: &mut Criterion) {
    let mut group = c.benchmark_group("orbit");
    let k = common::SIZES[0];
    let (_, _, map) = common::cube(k);
    for dim in 0..=3 {
        let starts = map.one_dart_per_cell(dim);
        let mask = AlphaMask::cell(3, dim);
        group.throughput(Throughput::Elements(map.dart_count() as u64));
        group.bench_with_input(BenchmarkId::new(format!("every_{dim}_cell"), k), &starts, |b, starts| {
            b.iter(|| starts.iter().map(|&d| map.orbit(d, mask).len()).sum::<usize>())
        });
    }
    group.finish();
}

criterion_group! { name = benches; config = common::config(); targets = orbit }
criterion_main!(benches);
