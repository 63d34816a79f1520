//! Replays the ambiguity test vectors of `tests/vectors/ambiguity/` (see `docs/ambiguity.md`):
//! every pair rebuilds both maps from their darts and from their constructions, and checks that
//! the maps are not isomorphic while their graphs are; every indexed vector reruns the g-map and
//! the indexed model. Each vector, recomputed from its constructions, is also an insta snapshot.

use std::path::Path;

use topomech::ambiguity::finder::Why;
use topomech::ambiguity::vector::Vector;
use topomech::graph::{graphs_isomorphic, GraphKind, Multiplicity};

fn vectors() -> Vec<Vector> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/vectors/ambiguity");
    let mut files: Vec<_> =
        std::fs::read_dir(&dir).expect("vector directory").map(|e| e.expect("entry").path()).collect();
    files.sort();
    files
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .map(|p| {
            let text = std::fs::read_to_string(p).expect("readable vector");
            serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        })
        .collect()
}

#[test]
fn every_vector_replays() {
    let all = vectors();
    assert!(all.len() >= 20, "the catalogue has {} vectors", all.len());
    for v in &all {
        v.check().unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn every_vector_is_reproduced_by_its_constructions() {
    for v in vectors() {
        let mut again = v.recompute().unwrap_or_else(|e| panic!("{e}"));
        // The graph's node order follows cell ids, which the kernel may assign differently:
        // compare it up to isomorphism, then keep the stored form.
        if let (Vector::Pair(new), Vector::Pair(old)) = (&mut again, &v) {
            let (g_new, g_old) = (new.graph.to_graph().expect("graph"), old.graph.to_graph().expect("graph"));
            assert!(graphs_isomorphic(&g_new, &g_old, Multiplicity::Match), "vector {}: graph changed", v.name());
            new.graph = old.graph.clone();
        }
        assert_eq!(again, v, "vector {} no longer matches its constructions", v.name());
        insta::assert_json_snapshot!(v.name().to_string(), again);
    }
}

#[test]
fn the_catalogue_covers_both_dimensions_and_the_classic_pairs() {
    let pairs: Vec<_> = vectors()
        .into_iter()
        .filter_map(|v| match v {
            Vector::Pair(p) => Some(*p),
            Vector::Indexed(_) => None,
        })
        .collect();
    assert!(pairs.iter().any(|p| p.dim == 2) && pairs.iter().any(|p| p.dim == 3));
    // Torus and Klein bottle: closed, χ = 0, one orientable; same incidence graph even with
    // multiplicities.
    let torus_klein = pairs.iter().any(|p| {
        p.graph_kind == GraphKind::Incidence
            && p.multiplicity == Multiplicity::Match
            && p.why == Why::Orientation
            && [&p.a.facts, &p.b.facts].iter().all(|f| f.boundary_darts == 0 && f.euler_characteristic == 0)
    });
    assert!(torus_klein);
    // The liver finding: a cut invisible to the 1-skeleton.
    assert!(pairs
        .iter()
        .any(|p| p.name == "ambiguity_campaign_skeleton_unchanged" && p.a.facts.cells[2] + 1 == p.b.facts.cells[2]));
}

#[test]
fn a_corrupted_vector_is_rejected() {
    let Some(Vector::Pair(mut p)) = vectors().into_iter().find(|v| matches!(v, Vector::Pair(_))) else {
        panic!("no pair vector")
    };
    p.b = p.a.clone();
    assert!(Vector::Pair(p).check().is_err(), "two identical maps are not an ambiguity");
}
