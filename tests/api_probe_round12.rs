//! Findings 68–69 of the twelfth API probing round (the ambiguity study's enumeration;
//! docs/VERIFICATION.md, "Findings"). Each test fails on the code before its fix.

use topomech::ambiguity::catalogue::{catalogue, Bounds};
use topomech::ambiguity::construct::cut_complexes;
use topomech::ambiguity::finder::complexes;

/// Finding 68: fewer than 4 points hold no tet: the enumeration is empty instead of panicking
/// on an index into the empty list of candidate tets.
#[test]
fn no_complex_on_fewer_than_four_points() {
    for points in 0..4 {
        assert!(cut_complexes(points, 2).is_empty(), "{points} points");
        assert_eq!(complexes(points, 2, 0, 0).tried(), 0, "{points} points");
    }
    let c = catalogue(Bounds { points: 3, ..Bounds::SMALL });
    assert_eq!(c.counts, catalogue(Bounds { points: 3, max_tets: 0, ..Bounds::SMALL }).counts);
}

/// Finding 69: `max_tets` bounds the complexes' size: 0 allows none (it enumerated all 1 337
/// complexes of up to 5 tets on 5 points), and every complex has at most `max_tets` tets.
#[test]
fn max_tets_bounds_every_complex() {
    assert!(cut_complexes(5, 0).is_empty());
    for max in 1..=3 {
        let all = cut_complexes(5, max);
        assert!(!all.is_empty() && all.iter().all(|c| c.tets.len() <= max), "max_tets {max}");
    }
    assert_eq!(cut_complexes(5, 1).len(), 1);
}
