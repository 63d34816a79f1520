//! Exhaustive small-scope checks of sew, unsew and isomorphism on every small n-G-map.

use crate::laws::{all_maps, check_sew, check_unsew};
use std::time::Instant;
use topomech::ops::{self, AlphaTable};
use topomech::{DartId, GMap};

/// The dart bound for dimension n: `TOPOMECH_PROOF_DARTS` if set, else a default that runs in a
/// few seconds (larger in release builds, where checks are ~20× faster).
fn max_darts(n: usize) -> usize {
    if let Some(k) = std::env::var("TOPOMECH_PROOF_DARTS").ok().and_then(|v| v.parse().ok()) {
        return k;
    }
    let release = !cfg!(debug_assertions);
    match (n, release) {
        (1, true) => 6,
        (1, false) => 5,
        (2, true) => 5,
        (2, false) => 4,
        (_, true) => 4,
        (_, false) => 3,
    }
}

/// Builds every map on 1..=max darts through the public API and checks every sew and unsew.
fn every_sew_and_unsew<const N: usize>() -> usize {
    let start = Instant::now();
    let mut maps = 0;
    for k in 1..=max_darts(N) {
        for table in all_maps::<N>(k) {
            let map =
                ops::from_alpha_table::<N>(&table).unwrap_or_else(|e| panic!("valid table {table:?} refused: {e}"));
            assert_eq!(ops::alpha_table(&map), table, "the rebuilt map differs from its table");
            ops::check_map_laws(&map).unwrap_or_else(|e| panic!("{table:?}: {e}"));
            check_all_operations(&map).unwrap_or_else(|e| panic!("n = {N}, table {table:?}: {e}"));
            maps += 1;
        }
    }
    eprintln!("n = {N}: {maps} maps on ≤ {} darts, every sew/unsew checked in {:?}", max_darts(N), start.elapsed());
    maps
}

fn check_all_operations<const N: usize>(map: &GMap<N>) -> Result<(), String> {
    let darts: Vec<DartId> = map.darts().collect();
    for i in 0..=N + 1 {
        for &a in &darts {
            for &b in &darts {
                check_sew(map, i, a, b)?;
            }
            if i <= N {
                check_unsew(map, i, a)?;
            }
        }
    }
    Ok(())
}

/// Number of labelled n-G-maps on k darts for small k, counted by hand for n = 1 (pairs of
/// involutions: I(k)², I = 1, 2, 4, 10, 26, 76 for k = 1..6) — the enumeration must be complete.
#[test]
fn enumeration_is_complete_for_n1() {
    let involutions = [1, 2, 4, 10, 26, 76];
    for (k, &count) in (1..=6).zip(&involutions) {
        assert_eq!(all_maps::<1>(k).len(), count * count, "k = {k}");
    }
    // n = 2 adds the law α0α2 = α2α0: on 2 darts, of the 8 tuples only those where α2 commutes
    // with α0 remain: α0 = id (2 choices of α1 × 2 of α2) + α0 = (01) (2 × 2) = 8, all commute.
    assert_eq!(all_maps::<2>(2).len(), 8);
    // On 3 darts (4 involutions: id and 3 transpositions): α0 = id leaves α1, α2 free (4·4);
    // α0 = (ab) allows α1 free (4) and α2 ∈ {id, (ab)} (2): 16 + 3·4·2 = 40.
    assert_eq!(all_maps::<2>(3).len(), 40);
}

#[test]
fn every_sew_and_unsew_n1() {
    assert!(every_sew_and_unsew::<1>() > 0);
}

#[test]
fn every_sew_and_unsew_n2() {
    assert!(every_sew_and_unsew::<2>() > 0);
}

#[test]
fn every_sew_and_unsew_n3() {
    assert!(every_sew_and_unsew::<3>() > 0);
}

/// The smallest relabelled table over all k! permutations: equal iff the maps are isomorphic.
fn canonical<const N: usize>(table: &AlphaTable) -> AlphaTable {
    let k = table.len();
    let mut best: Option<AlphaTable> = None;
    let mut perm: Vec<u32> = (0..k as u32).collect();
    loop {
        let mut t = vec![Vec::new(); k];
        for (r, row) in table.iter().enumerate() {
            t[perm[r] as usize] = row.iter().map(|&x| perm[x as usize]).collect();
        }
        if best.as_ref().is_none_or(|b| t < *b) {
            best = Some(t);
        }
        if !next_permutation(&mut perm) {
            return best.unwrap_or_default();
        }
    }
}

/// Lexicographic successor; false after the last permutation.
fn next_permutation(p: &mut [u32]) -> bool {
    let Some(i) = (1..p.len()).rev().find(|&i| p[i - 1] < p[i]) else { return false };
    let j = (i..p.len()).rev().find(|&j| p[j] > p[i - 1]).unwrap_or(i);
    p.swap(i - 1, j);
    p[i..].reverse();
    true
}

fn isomorphism_agrees_with_brute_force<const N: usize>(k: usize) -> usize {
    let tables = all_maps::<N>(k);
    let maps: Vec<GMap<N>> = tables.iter().map(|t| ops::from_alpha_table::<N>(t).unwrap()).collect();
    let canon: Vec<AlphaTable> = tables.iter().map(canonical::<N>).collect();
    let mut isomorphic_pairs = 0;
    for a in 0..maps.len() {
        for b in 0..maps.len() {
            let expected = canon[a] == canon[b];
            assert_eq!(maps[a].is_isomorphic(&maps[b]), expected, "{:?} vs {:?}", tables[a], tables[b]);
            isomorphic_pairs += usize::from(expected && a != b);
        }
    }
    isomorphic_pairs
}

#[test]
fn is_isomorphic_agrees_with_brute_force() {
    assert!(isomorphism_agrees_with_brute_force::<1>(4) > 0);
    assert!(isomorphism_agrees_with_brute_force::<2>(3) > 0);
    assert!(isomorphism_agrees_with_brute_force::<3>(3) > 0);
    if !cfg!(debug_assertions) {
        assert!(isomorphism_agrees_with_brute_force::<2>(4) > 0);
    }
}
