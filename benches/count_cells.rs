//! Cell counts on Kuhn cubes: by traversal (n + 1 floods), per dimension, and O(1) from the id
//! allocators. Throughput in darts.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

mod common;

fn count_cells(c: &mut Criterion) {
    let mut group = c.benchmark_group("count_cells");
    for k in common::SIZES {
        let (_, _, map) = common::cube(k);
        group.throughput(Throughput::Elements(map.dart_count() as u64));
        group.bench_with_input(BenchmarkId::new("by_traversal", k), &map, |b, map| {
            b.iter(|| std::hint::black_box(map).count_cells_by_traversal())
        });
        group.bench_with_input(BenchmarkId::new("components", k), &map, |b, map| {
            b.iter(|| std::hint::black_box(map).components().len())
        });
        for dim in 0..=3 {
            group.bench_with_input(
                BenchmarkId::new(format!("one_dart_per_cell_by_traversal_{dim}"), k),
                &map,
                |b, map| b.iter(|| std::hint::black_box(map).one_dart_per_cell_by_traversal(dim).len()),
            );
        }
        group.bench_with_input(BenchmarkId::new("o1_from_ids", k), &map, |b, map| {
            b.iter(|| std::hint::black_box(map).count_cells())
        });
    }
    group.finish();
}

criterion_group! { name = benches; config = common::config(); targets = count_cells }
criterion_main!(benches);
