//! Round 42: the spring coupling of a leveled map follows a cut (`LeveledMechanics::unsew_face`).
//! Laws checked after every cut of random cut/subdivide sequences, beside the coupling's own
//! `check` (which runs after every op under `expensive-checks` too):
//! - glued back (every vertex identified with its origin), the network is the one before the
//!   cut: per pair of origins, the same Σ k and Σ c, the same rest lengths (Kirchhoff's k = k₁ + k₂);
//! - the vertex masses summed by origin, Σ m u and Σ m are unchanged;
//! - every dart's vertex has the position and velocity its vertex had before the cut.
//!
//! A refused op changes nothing.

use std::collections::BTreeMap;

use proptest::prelude::*;
use topomech::mechanics::Vec3;
use topomech::subdivide::fuzz::{decode, Mesh, Op, MAX_DARTS};
use topomech::subdivide::{CouplingError, LeveledMap, LeveledMechanics, SpringLawError, SubdivideError};
use topomech::DartId;

mod subdivide_common;
use subdivide_common::{apply_coupled, cube, material, moving_coupling, sewn, tet_mesh, TET};

/// What a cut must keep, read off the coupling glued back: per pair of origins (smaller first)
/// the sums of k and c and the sorted rest lengths; per origin the vertex mass; Σ m u; per dart
/// its vertex's position and velocity.
#[derive(Debug)]
struct Glued {
    pairs: BTreeMap<(u32, u32), (f64, f64, Vec<f64>)>,
    masses: BTreeMap<u32, f64>,
    momentum: Vec3,
    scale: f64,
    states: BTreeMap<DartId, (Vec3, Vec3)>,
}

impl Glued {
    fn of(mech: &LeveledMechanics, m: &LeveledMap<3>) -> Glued {
        let o = |v: u32| m.vertex_origin(v);
        let mut pairs: BTreeMap<(u32, u32), (f64, f64, Vec<f64>)> = BTreeMap::new();
        for (e, s) in mech.springs() {
            let (a, b) = (o(e.a).min(o(e.b)), o(e.a).max(o(e.b)));
            let entry = pairs.entry((a, b)).or_default();
            entry.0 += s.stiffness;
            entry.1 += s.damping;
            entry.2.push(s.rest);
        }
        for p in pairs.values_mut() {
            p.2.sort_by(f64::total_cmp);
            p.2.dedup();
        }
        let mass = mech.vertex_masses(m).unwrap();
        let mut masses: BTreeMap<u32, f64> = BTreeMap::new();
        let (mut momentum, mut scale) = ([0.0; 3], 0.0);
        for d in m.map().one_dart_per_cell(0) {
            let v = m.map().vertex_id(d).0;
            *masses.entry(o(v)).or_default() += mass[v as usize];
            for (p, u) in momentum.iter_mut().zip(mech.velocity[v as usize]) {
                *p += mass[v as usize] * u;
                scale += (mass[v as usize] * u).abs();
            }
        }
        let states = m
            .map()
            .darts()
            .map(|x| {
                let v = m.map().vertex_id(x).index();
                (x, (mech.position[v], mech.velocity[v]))
            })
            .collect();
        Glued { pairs, masses, momentum, scale, states }
    }

    /// The laws of a cut: `after` (the state after a cut) glued back is `self`.
    fn kept_by(&self, after: &Glued) -> Result<(), String> {
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * x.abs().max(y.abs());
        if self.pairs.keys().ne(after.pairs.keys()) {
            return Err("the pairs of origins joined by springs changed".into());
        }
        for (pair, (k, c, rest)) in &self.pairs {
            let (k2, c2, rest2) = &after.pairs[pair];
            if !close(*k, *k2) || !close(*c, *c2) {
                return Err(format!("origins {pair:?}: k {k} → {k2}, c {c} → {c2}"));
            }
            if rest != rest2 {
                return Err(format!("origins {pair:?}: rest lengths {rest:?} → {rest2:?}"));
            }
        }
        for (v, &x) in &self.masses {
            let y = after.masses.get(v).copied().unwrap_or(f64::NAN);
            if !close(x, y) {
                return Err(format!("origin {v}: mass {x} → {y}"));
            }
        }
        for k in 0..3 {
            if (self.momentum[k] - after.momentum[k]).abs() > 1e-12 * self.scale.max(1e-300) {
                return Err(format!("Σ m u {:?} → {:?}", self.momentum, after.momentum));
            }
        }
        match self.states.iter().find(|(x, s)| after.states.get(x) != Some(s)) {
            Some((x, s)) => Err(format!("dart {x:?}: state {s:?} → {:?}", after.states.get(x))),
            None => Ok(()),
        }
    }
}

/// Runs the ops decoded in cut mode with the coupling: every law of `check` after every op, the
/// glued laws after every cut, a refused op changes nothing. Returns the cuts applied.
fn run(bytes: &[u8]) -> Result<usize, String> {
    let mut bytes = bytes.to_vec();
    bytes[0] |= 0x80;
    let (mesh, ops) = decode(&bytes);
    let mut m = match mesh {
        Mesh::Tet => tet_mesh(TET.to_vec(), &[[0, 1, 2, 3]]),
        _ => cube(if bytes[0] & 1 == 0 { 1 } else { 2 }),
    };
    let mut mech = moving_coupling(&m)?;
    let mut cuts = 0;
    for (k, &op) in ops.iter().enumerate() {
        if m.map().dart_count() >= MAX_DARTS {
            break;
        }
        let (before, version, glued) = (mech.clone(), m.version(), Glued::of(&mech, &m));
        let Some(result) = apply_coupled(&mut mech, &mut m, op) else { continue };
        match result {
            Ok(()) if matches!(op, Op::Cut { .. }) => {
                cuts += 1;
                glued.kept_by(&Glued::of(&mech, &m)).map_err(|e| format!("op {k} {op:?}: {e}"))?;
            }
            Ok(()) => {}
            Err(CouplingError::Subdivide(_)) if !matches!(op, Op::Around { .. }) => {
                if mech != before || m.version() != version {
                    return Err(format!("op {k} {op:?} refused but something changed"));
                }
            }
            Err(CouplingError::Subdivide(_)) => {}
            Err(e) => return Err(format!("op {k} {op:?}: {e}")),
        }
        mech.check(&m).map_err(|e| format!("op {k} {op:?}: {e}"))?;
    }
    Ok(cuts)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    #[test]
    fn cuts_among_random_subdivisions_keep_every_spring_law(bytes in proptest::collection::vec(any::<u8>(), 1..31)) {
        if let Err(e) = run(&bytes) {
            prop_assert!(false, "{}", e);
        }
    }
}

#[test]
fn the_fuzz_corpus_in_cut_mode_keeps_every_spring_law_with_the_coupling() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/subdivide");
    let (mut files, mut cuts) = (0, 0);
    for entry in std::fs::read_dir(dir).unwrap() {
        let bytes = std::fs::read(entry.unwrap().path()).unwrap();
        if bytes.is_empty() || decode(&bytes).0 == Mesh::Grid {
            continue;
        }
        cuts += run(&bytes).unwrap_or_else(|e| panic!("{e}"));
        files += 1;
    }
    assert!(files >= 20 && cuts >= 20, "{files} files, {cuts} cuts");
}

/// Kuhn cube k = 2 refined around its centre to level 2, with its coupling.
fn refined_cube() -> (LeveledMap<3>, LeveledMechanics) {
    let mut m = cube(2);
    let mut mech = LeveledMechanics::new(&m, material()).unwrap();
    mech.refine_around(&mut m, [1.0, 1.0, 1.0], 0.3, 2).unwrap();
    (m, mech)
}

/// The inner faces (one dart each) whose vertices all lie on the plane x = 1.
fn plane_faces(m: &LeveledMap<3>) -> Vec<DartId> {
    let map = m.map();
    let on_plane = |d: DartId| {
        let face = map.orbit(d, topomech::AlphaMask::of(&[0, 1]));
        face.iter().all(|&x| m.points()[map.vertex_id(x).index()][0] == 1.0)
    };
    let mut seen = std::collections::BTreeSet::new();
    map.darts().filter(|&d| !map.is_free(3, d) && seen.insert(map.cell_id(2, d)) && on_plane(d)).collect()
}

/// Connected components of the graph of the springs (vertex ids as they are).
fn spring_components(mech: &LeveledMechanics, m: &LeveledMap<3>) -> usize {
    let n = m.map().cell_id_bound(0);
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], x: usize) -> usize {
        let mut r = x;
        while p[r] != r {
            r = p[r];
        }
        p[x] = r;
        r
    }
    for (e, _) in mech.springs() {
        let (a, b) = (find(&mut parent, e.a as usize), find(&mut parent, e.b as usize));
        parent[a] = b;
    }
    let live: std::collections::BTreeSet<usize> =
        m.map().darts().map(|d| m.map().vertex_id(d).index()).map(|v| find(&mut parent, v)).collect();
    live.len()
}

#[test]
fn a_cut_through_a_refined_cube_separates_the_springs_and_keeps_every_sum() {
    let (mut m, mut mech) = refined_cube();
    let level = m.max_level() + 1;
    let faces = plane_faces(&m);
    assert!(faces.len() >= 8, "{} faces on the plane", faces.len());
    let glued = Glued::of(&mech, &m);
    assert_eq!(spring_components(&mech, &m), 1);
    for &f in &faces {
        // The plane's faces at the finest level, cut one by one, all at a new level.
        mech.unsew_face(&mut m, f, level).unwrap();
        mech.check(&m).unwrap();
    }
    glued.kept_by(&Glued::of(&mech, &m)).unwrap();
    assert_eq!(spring_components(&mech, &m), 2, "the cube falls in two");
    // Some half of a refined edge on the plane was cut into two parts in parallel: a root's
    // chain holds two springs between the same origins.
    let o = |v: u32| m.vertex_origin(v);
    let parallel = mech.roots().any(|(e, _)| {
        let ends: Vec<(u32, u32)> = mech.chain(e).iter().map(|h| (o(h.a).min(o(h.b)), o(h.a).max(o(h.b)))).collect();
        (1..ends.len()).any(|i| ends[..i].contains(&ends[i]))
    });
    assert!(parallel, "a cut half stands in parallel in its chain");
    // The refinement goes on across the cut: split every part of the plane's split edges again.
    let parts: Vec<DartId> = m
        .map()
        .darts()
        .filter(|&d| {
            let e = topomech::subdivide::EdgeKey::of(m.map(), d);
            let x = |v: u32| m.points()[v as usize][0];
            x(e.a) == 1.0 && x(e.b) == 1.0 && m.map().is_free(3, d)
        })
        .take(6)
        .collect();
    let top = m.max_level();
    for d in parts {
        if m.map().contains(d) {
            match mech.split_edge(&mut m, d, top + 1) {
                Ok(_) | Err(CouplingError::Subdivide(_)) => {}
                Err(e) => panic!("{e}"),
            }
            mech.check(&m).unwrap();
        }
    }
}

#[test]
fn shares_moved_between_the_parts_of_a_cut_edge_are_flagged() {
    let (mut m, mut mech) = refined_cube();
    let level = m.max_level();
    for f in plane_faces(&m) {
        mech.unsew_face(&mut m, f, level).unwrap();
    }
    mech.check(&m).unwrap();
    let o = |v: u32| m.vertex_origin(v);
    let mut by_pair: BTreeMap<(u32, u32), Vec<topomech::subdivide::EdgeKey>> = BTreeMap::new();
    for (e, _) in mech.springs() {
        by_pair.entry((o(e.a).min(o(e.b)), o(e.a).max(o(e.b)))).or_default().push(e);
    }
    let halves: std::collections::BTreeSet<_> = mech.roots().flat_map(|(r, _)| mech.chain(r)).collect();
    let (mut whole, mut half) = (0, 0);
    for parts in by_pair.values().filter(|p| p.len() == 2) {
        let is_half = halves.contains(&parts[0]);
        // Move a tenth of one part's stiffness to the other: Σ k is kept, the shares are not.
        let mut bad = mech.clone();
        let moved = 0.1 * bad.spring_at(parts[0]).unwrap().stiffness;
        bad.spring_mut(parts[0]).unwrap().stiffness -= moved;
        bad.spring_mut(parts[1]).unwrap().stiffness += moved;
        match (is_half, bad.check(&m)) {
            // An edge that is no half: each part is its own tets' law 5.
            (false, Err(SpringLawError::Stiffness { .. })) => whole += 1,
            // A half: law 4 sees only the glued sum; the parallel sum is unchanged, so it holds.
            (true, Ok(())) => {
                half += 1;
                // Doubling one part's stiffness breaks the glued chain's compliance.
                bad.spring_mut(parts[0]).unwrap().stiffness *= 2.0;
                assert!(matches!(bad.check(&m), Err(SpringLawError::Series { .. })));
            }
            (h, r) => panic!("half {h}: {r:?}"),
        }
    }
    assert!(whole > 0 && half > 0, "{whole} whole edges, {half} halves cut");
}

#[test]
fn a_refused_cut_changes_nothing_and_a_cut_behind_the_back_is_refused() {
    let (mut m, mut mech) = refined_cube();
    let free = m.map().darts().find(|&d| m.map().is_free(3, d)).unwrap();
    let (before, version, top, inner) = (mech.clone(), m.version(), m.max_level(), sewn(&m, 0));
    let e = mech.unsew_face(&mut m, free, top).unwrap_err();
    assert!(matches!(e, CouplingError::Subdivide(SubdivideError::FaceNotSewn(_))), "{e}");
    let e = mech.unsew_face(&mut m, DartId(u32::MAX), top).unwrap_err();
    assert!(matches!(e, CouplingError::Subdivide(SubdivideError::NoSuchDart(_))), "{e}");
    let e = mech.unsew_face(&mut m, inner, 0).unwrap_err();
    assert!(matches!(e, CouplingError::Subdivide(SubdivideError::LevelBelowMax { .. })), "{e}");
    assert_eq!((&mech, m.version()), (&before, version));
    // The map cut alone: the coupling refuses to go on.
    m.unsew_face(inner, top).unwrap();
    let next = sewn(&m, 1);
    let e = mech.unsew_face(&mut m, next, top).unwrap_err();
    assert!(matches!(e, CouplingError::StateCount { .. } | CouplingError::Unfollowed { .. }), "{e}");
}
