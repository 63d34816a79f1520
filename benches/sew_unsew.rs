//! `unsew::<3>` of a seeded 10 % of the interior faces of a Kuhn cube, then `sew::<3>` of the same
//! faces back (cell ids kept exact); throughput in operations.

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput};
use topomech::generate::SplitMix64;
use topomech::DartId;

mod common;

fn sew_unsew(c: &mut Criterion) {
    let mut group = c.benchmark_group("sew_unsew");
    let k = common::SIZES[0];
    let (_, _, map) = common::cube(k);
    let mut rng = SplitMix64(2024);
    let cut: Vec<DartId> =
        map.one_dart_per_cell(2).into_iter().filter(|&d| !map.is_free(3, d) && rng.below(10) == 0).collect();
    let partners: Vec<DartId> = cut.iter().map(|&d| map.alpha::<3>(d)).collect();
    let mut cut_map = map.clone();
    cut.iter().for_each(|&d| drop(cut_map.unsew::<3>(d).expect("interior face")));
    group.throughput(Throughput::Elements(cut.len() as u64));
    group.bench_function(BenchmarkId::new("unsew3_random_10pc", k), |b| {
        b.iter_batched_ref(
            || map.clone(),
            |m| cut.iter().for_each(|&d| drop(m.unsew::<3>(d).expect("interior face"))),
            BatchSize::LargeInput,
        )
    });
    group.bench_function(BenchmarkId::new("sew3_back", k), |b| {
        b.iter_batched_ref(
            || cut_map.clone(),
            |m| cut.iter().zip(&partners).for_each(|(&d, &e)| drop(m.sew::<3>(d, e).expect("sewable"))),
            BatchSize::LargeInput,
        )
    });
    group.finish();
}

criterion_group! { name = benches; config = common::config(); targets = sew_unsew }
criterion_main!(benches);
