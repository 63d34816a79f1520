//! Laws shared by the exhaustive checks and the Kani harnesses.

use topomech::gmap::Law;
use topomech::ops::{self, AlphaTable};
use topomech::{DartId, GMap, InvariantViolation};

/// Every involution on 0..k, as image tables. Built iteratively (no recursion): each partial
/// involution is extended at its first unassigned point, by a fixed point or a pair.
pub fn involutions(k: usize) -> Vec<Vec<u32>> {
    let mut done = Vec::new();
    let mut partial = vec![vec![u32::MAX; k]];
    while let Some(p) = partial.pop() {
        let Some(x) = p.iter().position(|&v| v == u32::MAX) else {
            done.push(p);
            continue;
        };
        let mut fixed = p.clone();
        fixed[x] = x as u32;
        partial.push(fixed);
        for y in x + 1..k {
            if p[y] == u32::MAX {
                let mut paired = p.clone();
                paired[x] = y as u32;
                paired[y] = x as u32;
                partial.push(paired);
            }
        }
    }
    done
}

/// Whether αi∘αj is an involution, i.e. αi and αj commute (both being involutions).
fn commute(a: &[u32], b: &[u32]) -> bool {
    (0..a.len()).all(|x| a[b[x] as usize] == b[a[x] as usize])
}

/// Every n-G-map on exactly k darts, as alpha tables (rows = darts).
pub fn all_maps<const N: usize>(k: usize) -> Vec<AlphaTable> {
    let invs = involutions(k);
    let mut tuples: Vec<Vec<&Vec<u32>>> = vec![Vec::new()];
    for i in 0..=N {
        let mut next = Vec::new();
        for t in &tuples {
            for inv in &invs {
                if (0..(i.saturating_sub(1))).all(|j| commute(t[j], inv)) {
                    let mut u = t.clone();
                    u.push(inv);
                    next.push(u);
                }
            }
        }
        tuples = next;
    }
    tuples.into_iter().map(|t| (0..k).map(|d| t.iter().map(|inv| inv[d]).collect()).collect()).collect()
}

/// The checks of one i-sew attempt of (a, b) on `map`: agreement with `is_sewable`; a refusal
/// leaves the map slot-for-slot unchanged; an accepted sew leaves a valid map with exact cell
/// ids and a consistent report, which an unsew of a undoes up to isomorphism.
pub fn check_sew<const N: usize>(map: &GMap<N>, i: usize, a: DartId, b: DartId) -> Result<(), String> {
    let op = topomech::ops::KernelOp::Sew { i: i as u8, a: a.0, b: b.0 };
    let mut after = map.clone();
    let result = ops::apply(&mut after, &op);
    if result.is_ok() != map.is_sewable_dyn(i, a, b) {
        return Err(format!("is_sewable({i}, {a:?}, {b:?}) disagrees with sew: {result:?}"));
    }
    // The compile-time-index version gives the same answer (i = 0, 1 exist for every n ≥ 1).
    let fixed = match i {
        0 => Some(map.is_sewable::<0>(a, b)),
        1 => Some(map.is_sewable::<1>(a, b)),
        _ => None,
    };
    if fixed.is_some_and(|f| f != result.is_ok()) {
        return Err(format!("is_sewable::<{i}>({a:?}, {b:?}) disagrees with sew: {result:?}"));
    }
    ops::check_after_op(map, &after, &op, &result)
}

/// The checks of one i-unsew of d (see [`check_sew`]).
pub fn check_unsew<const N: usize>(map: &GMap<N>, i: usize, d: DartId) -> Result<(), String> {
    let op = topomech::ops::KernelOp::Unsew { i: i as u8, a: d.0 };
    let mut after = map.clone();
    let result = ops::apply(&mut after, &op);
    if result.is_ok() == map.is_free(i, d) {
        return Err(format!("unsew({i}, {d:?}) accepted a free dart or refused a sewn one: {result:?}"));
    }
    ops::check_after_op(map, &after, &op, &result)
}

/// Laws a raw map breaks, found here without `validate()`. Link laws first: when one is broken
/// orbits are not defined, so cell laws are only looked at when every link law holds. The
/// quasi-manifold law is read literally (αi(αj(d)) ≠ αj(αi(d)) where αj(d) and αi(d) are live,
/// the final images being compared raw, as `validate()` does), so a map whose involution law is
/// broken may break it too, and `validate()` may name it first (it checks both laws dart by
/// dart; see docs/VERIFICATION.md, findings).
pub fn broken_laws<const N: usize>(map: &GMap<N>) -> Vec<Law> {
    let mut laws = Vec::new();
    let alpha = |i: usize, d: DartId| Some(map.alpha_dyn(i, d)).filter(|&e| map.contains(e));
    for d in map.darts() {
        for i in 0..=N {
            if alpha(i, d).and_then(|e| alpha(i, e)) != Some(d) {
                laws.push(Law::Involution);
            }
            for j in i + 2..=N {
                // The last image may be a dead slot: validate() compares raw values there.
                let ij = alpha(j, d).map(|e| map.alpha_dyn(i, e));
                let ji = alpha(i, d).map(|e| map.alpha_dyn(j, e));
                if ij.is_some() && ji.is_some() && ij != ji {
                    laws.push(Law::QuasiManifold);
                }
            }
        }
    }
    if !laws.is_empty() {
        return laws;
    }
    cell_laws(map)
}

fn cell_laws<const N: usize>(map: &GMap<N>) -> Vec<Law> {
    let mut laws = Vec::new();
    for dim in 0..=N {
        for d in map.darts() {
            let id = map.cell_id(dim, d);
            let differs = (0..=N).filter(|&j| j != dim).any(|j| map.cell_id(dim, map.alpha_dyn(j, d)) != id);
            if differs || !map.is_live_cell(dim, id) {
                laws.push(Law::CellIdConstant);
            }
        }
    }
    if !laws.is_empty() {
        return laws;
    }
    for dim in 0..=N {
        let cells = map.one_dart_per_cell_by_traversal(dim);
        let mut ids: Vec<u32> = cells.iter().map(|&d| map.cell_id(dim, d).0).collect();
        ids.sort_unstable();
        ids.dedup();
        let live = (0..map.cell_id_bound(dim) as u32).filter(|&id| map.is_live_cell(dim, topomech::CellId(id))).count();
        if ids.len() != cells.len() || live != cells.len() {
            laws.push(Law::CellIdUnique);
        }
    }
    laws
}

/// The witness of a violation is true of the map.
pub fn witness_holds<const N: usize>(map: &GMap<N>, v: &InvariantViolation) -> bool {
    use InvariantViolation::*;
    match *v {
        DanglingLink { dart, i, target } => map.alpha_dyn(i, dart) == target && !map.contains(target),
        NotInvolution { dart, i, image, back } => {
            map.alpha_dyn(i, dart) == image && map.alpha_dyn(i, image) == back && back != dart
        }
        QuasiManifold { dart, i, j, ij, ji } => {
            j >= i + 2
                && map.alpha_dyn(i, map.alpha_dyn(j, dart)) == ij
                && map.alpha_dyn(j, map.alpha_dyn(i, dart)) == ji
                && ij != ji
        }
        CellIdDiffers { dart, dim, j, id, other, other_id } => {
            j != dim
                && map.alpha_dyn(j, dart) == other
                && map.cell_id(dim, dart) == id
                && map.cell_id(dim, other) == other_id
                && id != other_id
        }
        CellIdNotLive { dart, dim, id } => map.cell_id(dim, dart) == id && !map.is_live_cell(dim, id),
        CellIdShared { dim, id, first, second } => {
            map.cell_id(dim, first) == id
                && map.cell_id(dim, second) == id
                && !map.cell_darts(dim, first).contains(&second)
        }
        CellIdOrphan { dim, id } => map.is_live_cell(dim, id) && map.darts().all(|d| map.cell_id(dim, d) != id),
        TetLayout { dart, i, stored, built } => {
            map.tets_as_built() && stored != built && (!map.contains(dart) || map.alpha_dyn(i, dart) == stored)
        }
    }
}

/// The law `validate()` must name when several are broken: the first in the order of its table
/// (a broken involution is the cause, not the quasi-manifold failure a neighbour then shows).
fn first_in_table_order(broken: &[Law]) -> Option<Law> {
    [Law::Involution, Law::QuasiManifold, Law::CellIdConstant, Law::CellIdUnique, Law::TetLayout]
        .into_iter()
        .find(|l| broken.contains(l))
}

/// `validate()` fails iff [`broken_laws`] finds a law broken, names the first of them in table
/// order, with a true witness.
pub fn check_validate_names_law<const N: usize>(map: &GMap<N>) -> Result<(), String> {
    let broken = broken_laws(map);
    match map.validate() {
        Ok(()) if broken.is_empty() => Ok(()),
        Ok(()) => Err(format!("validate() passed but {broken:?} are broken")),
        Err(e) if !broken.contains(&e.law()) => {
            Err(format!("validate() says `{e}` ({:?}) but the broken laws are {broken:?}", e.law()))
        }
        Err(e) if Some(e.law()) != first_in_table_order(&broken) => Err(format!(
            "validate() says `{e}` ({:?}) but the first broken law in table order is {:?}",
            e.law(),
            first_in_table_order(&broken)
        )),
        Err(e) if !witness_holds(map, &e) => Err(format!("validate() says `{e}`, which is not true of the map")),
        Err(_) => Ok(()),
    }
}
