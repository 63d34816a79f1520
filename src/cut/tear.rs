//! Tearing (seed §5.1, Fig. 10): split a vertex whose inner stress is too high by dissociating the
//! closed fan of faces around it, starting from the face whose normal best matches the stress.
//!
//! The fan walk from a dart d0 of the start face at vertex v: d_{k+1} = α1 α2 α3 α2 (d_k) (apply
//! α2, then α3, α2, α1). α2 turns to the other face of the tet on the current edge, α3 crosses into
//! the neighbouring tet, α2 turns to the other face of that tet on the same edge, α1 moves to the
//! other edge of that face at v. No α0 is used, so every dart stays on v. The walk stops when it
//! comes back to d0, or before an α3 that is free (the surface); in that case it starts again from
//! α1(d0) to collect the other half of the fan.

use crate::mechanics::geom::{cross, dot, sub};
use crate::mechanics::model::{closed_triangle_vertices, triangle_vertices};
use crate::mechanics::{Body, SimError, Simulation, TouchedCells, Vec3};
use crate::{AlphaMask, CellId, DartId, GMap};

use super::sweep::Scaled;
use super::{dissociate_face, CutError, Dissociation};

/// The tensile stress at a vertex: the largest principal value of σ_v = Σ_s T_s n_s n_sᵀ over the
/// springs at v, with T_s = max(0, k_s (l_s − L_s)) the spring's tension and n_s its unit
/// direction, and the principal direction.
///
/// # Examples
///
/// ```
/// use topomech::cut::principal_stress;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-3)).unwrap();
/// body.attrs_mut().position_mut().as_mut_slice()[7][0] += 0.5; // pull a corner along x
/// let s = principal_stress(&body, &sim).unwrap()[7];
/// let norm = s.direction.iter().map(|c| c * c).sum::<f64>().sqrt();
/// assert!(s.magnitude > 0.0 && (norm - 1.0).abs() < 1e-9);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stress {
    /// The largest eigenvalue of σ_v (a force: the "inner force" compared with the threshold).
    pub magnitude: f64,
    /// Its unit eigenvector (zero when the magnitude is zero).
    pub direction: Vec3,
}

/// What tearing one vertex did.
///
/// # Examples
///
/// ```
/// use topomech::cut::tear_vertex;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Material};
/// use topomech::CellId;
///
/// let (points, tets) = kuhn_cube(2);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let tear = tear_vertex(&mut body, CellId(13), [0.0, 0.0, 1.0], None).unwrap();
/// assert_eq!(tear.vertex, CellId(13));
/// assert!(tear.split && tear.dissociations.len() <= tear.fan.len());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Tear {
    /// The vertex torn.
    pub vertex: CellId,
    /// One dart per fan face, in walk order (first half, then the second half).
    pub fan: Vec<DartId>,
    /// Dissociations of the fan's inner faces.
    pub dissociations: Vec<Dissociation>,
    /// Whether the vertex was split (some dissociation split `vertex`).
    pub split: bool,
    /// Everything the projection must re-read.
    pub touched: TouchedCells,
}

/// What [`tear_step`] did.
///
/// # Examples
///
/// ```
/// use topomech::cut::{tear_step, TearStep};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};
///
/// let (points, tets) = kuhn_cube(2);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let mut sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-4)).unwrap();
/// assert_eq!(tear_step(&mut body, &mut sim, 1.0, 4).unwrap(), TearStep::default()); // nothing at rest
/// body.attrs_mut().position_mut().as_mut_slice()[13][0] += 0.5;
/// assert_eq!(tear_step(&mut body, &mut sim, 1.0, 1).unwrap().tears[0].vertex.0, 13);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TearStep {
    /// One entry per torn vertex.
    pub tears: Vec<Tear>,
}

/// σ_v's principal pair for every vertex slot of `sim`'s projection, from `body`'s current
/// positions. O(springs + slots).
///
/// # Errors
/// [`SimError::OtherBody`] when `sim` was not built for `body`
/// ([`crate::mechanics::Projection::is_for`]: its slots and springs are another body's), and
/// [`SimError::StaleProjection`] when `body` changed topologically since `sim` last followed it
/// (its springs may join vertices that no longer exist).
///
/// [`SimError::OtherBody`]: crate::mechanics::SimError::OtherBody
/// [`SimError::StaleProjection`]: crate::mechanics::SimError::StaleProjection
///
/// # Examples
///
/// ```
/// use topomech::cut::principal_stress;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};
///
/// let (points, tets) = kuhn_cube(1);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-3)).unwrap();
/// assert!(principal_stress(&body, &sim).unwrap().iter().all(|s| s.magnitude == 0.0)); // at rest
/// body.attrs_mut().position_mut().as_mut_slice()[7][2] += 0.5; // pull the top corner up
/// let stress = principal_stress(&body, &sim).unwrap();
/// assert!(stress[7].magnitude > 0.0 && stress[7].direction[2].abs() > 0.5);
/// assert!(principal_stress(&body.clone(), &sim).is_err()); // another body
/// ```
pub fn principal_stress(body: &Body, sim: &Simulation) -> Result<Vec<Stress>, SimError> {
    sim.check_current(body)?;
    let sys = &sim.projection.system;
    let x = body.attrs().position.as_slice();
    let mut sigma = vec![[[0.0f64; 3]; 3]; sys.slots()];
    for s in 0..sys.springs() {
        let [a, b] = sys.ends[s];
        let d = sub(x[b as usize], x[a as usize]);
        let l = dot(d, d).sqrt();
        let tension = sys.stiffness[s] * (l - sys.rest[s]);
        if l == 0.0 || tension <= 0.0 {
            continue;
        }
        for v in [a, b] {
            for (i, row) in sigma[v as usize].iter_mut().enumerate() {
                for (j, e) in row.iter_mut().enumerate() {
                    *e += tension * d[i] * d[j] / (l * l);
                }
            }
        }
    }
    Ok(sigma.iter().map(largest_eigenpair).collect())
}

/// Largest eigenpair of a symmetric positive semi-definite 3×3 matrix by power iteration started
/// from its largest column (64 iterations at most). O(1).
fn largest_eigenpair(m: &[[f64; 3]; 3]) -> Stress {
    let mut v =
        (0..3).map(|j| [m[0][j], m[1][j], m[2][j]]).fold([0.0; 3], |a, c| if dot(c, c) > dot(a, a) { c } else { a });
    if dot(v, v) == 0.0 {
        return Stress { magnitude: 0.0, direction: [0.0; 3] };
    }
    let mut lambda = 0.0;
    for _ in 0..64 {
        let w = mul(m, v);
        let n = dot(w, w).sqrt();
        if n == 0.0 {
            break;
        }
        v = [w[0] / n, w[1] / n, w[2] / n];
        let next = dot(v, mul(m, v));
        let done = (next - lambda).abs() <= 1e-14 * next.abs();
        lambda = next;
        if done {
            break;
        }
    }
    Stress { magnitude: lambda, direction: v }
}

/// One dart per face of the fan around the vertex of `d0`, starting with `d0`'s face, in walk
/// order (module docs). Faces met twice are listed once. Every walk is bounded by the dart count.
/// O(fan). Empty when `d0` is not a live dart.
///
/// # Examples
///
/// ```
/// use topomech::cut::fan_darts;
/// use topomech::generate::kuhn_cube;
/// use topomech::GMap;
///
/// let (points, tets) = kuhn_cube(2);
/// let (map, _) = GMap::<3>::from_tets(points.len(), &tets).unwrap();
/// let d = map.darts().find(|&d| map.vertex_id(d).0 == 13).unwrap(); // the centre (1, 1, 1)
/// let fan = fan_darts(&map, d);
/// assert_eq!(fan[0], d);
/// assert!(fan.len() > 2 && fan.iter().all(|&e| map.vertex_id(e).0 == 13));
/// assert!(fan_darts(&map, topomech::DartId(u32::MAX)).is_empty()); // no such dart: no fan
/// ```
pub fn fan_darts(map: &GMap<3>, d0: DartId) -> Vec<DartId> {
    if !map.contains(d0) {
        return Vec::new();
    }
    let mut faces: Vec<CellId> = Vec::with_capacity(16);
    let mut out = Vec::with_capacity(16);
    let mut push = |d: DartId, out: &mut Vec<DartId>| {
        let f = map.cell_id(2, d);
        if !faces.contains(&f) {
            faces.push(f);
            out.push(d);
        }
    };
    let closed = walk(map, d0, |d| push(d, &mut out));
    if !closed {
        let mut second = Vec::new();
        walk(map, map.alpha::<1>(d0), |d| second.push(d));
        for d in second {
            push(d, &mut out);
        }
    }
    out
}

/// Walks α2 α3 α2 α1 from `start`, visiting each dart; true if it came back to `start`.
fn walk(map: &GMap<3>, start: DartId, mut visit: impl FnMut(DartId)) -> bool {
    let mut d = start;
    for _ in 0..=map.dart_count() {
        visit(d);
        let x = map.alpha::<2>(d);
        if map.is_free(3, x) {
            return false;
        }
        d = map.alpha::<1>(map.alpha::<2>(map.alpha::<3>(x)));
        if d == start {
            return true;
        }
    }
    false
}

/// Unit normal of the triangle with sorted vertex ids `[a, b, c]` from current positions (zero
/// if degenerate). O(1).
fn triangle_normal(body: &Body, [a, b, c]: [CellId; 3]) -> Vec3 {
    let mech = body.attrs();
    let p = |v: CellId| mech.position[v];
    // The edges and their cross product scaled by powers of two to a largest component in
    // [1, 2) (exact): no overflow or underflow at any coordinate scale (finding 85). For ordinary
    // coordinates the unit normal is the unscaled one bit for bit.
    let (e1, e2) = (Scaled::diff(p(b), p(a), 0).dir, Scaled::diff(p(c), p(a), 0).dir);
    let n = Scaled::new(cross(e1, e2), 0, 0).dir;
    let len = dot(n, n).sqrt();
    if len == 0.0 {
        return [0.0; 3];
    }
    [n[0] / len, n[1] / len, n[2] / len]
}

/// Unit normal of the face of `d` from current positions (zero if it is not a triangle with
/// three distinct vertices, or degenerate). O(face).
fn face_normal(body: &Body, d: DartId) -> Vec3 {
    triangle_vertices(body.map(), d).map_or([0.0; 3], |t| triangle_normal(body, t))
}

/// [`face_normal`] for a dart `x` of the vertex being torn, reading the face's vertices off
/// three darts instead of walking its orbit: when the face ⟨α0, α1⟩(x) closes after six darts
/// (x, α0 x, α1 α0 x, α0 α1 α0 x = α1 α0 α1 x, α0 α1 x, α1 x) its vertices are those of x,
/// α0 x and α0 α1 x ([`closed_triangle_vertices`]); if they are distinct, that is
/// [`triangle_vertices`]' sorted triple and the normal is the same bit for bit. Otherwise falls
/// back to [`face_normal`]. O(1).
fn face_normal_at(body: &Body, x: DartId) -> Vec3 {
    let map = body.map();
    // A face of a tet as built is a closed hexagon (the layout law), so the test is skipped then.
    let closed = map.tets_as_built() || {
        let (a, b) = (map.alpha_local(0, x), map.alpha_local(1, x));
        let c = map.alpha_local(0, b);
        a != x && b != x && c != b && map.alpha_local(0, map.alpha_local(1, a)) == map.alpha_local(1, c)
    };
    match closed.then(|| closed_triangle_vertices(map, x)).flatten() {
        Some(ids) => triangle_normal(body, ids),
        None => face_normal(body, x),
    }
}

/// The dart starting the fan of the vertex of `start`: among its inner darts, the one whose face
/// normal is closest to ±`direction` (highest |n · direction|), the smallest dart on ties;
/// `None` if every face at the vertex is on the boundary.
///
/// A face's score depends only on its vertices, shared by x, α1(x), α3(x), α1α3(x): only the
/// smallest of the four is scored, with the O(1) normal of [`face_normal_at`]. The choice is
/// that of scoring every inner dart (unit test): every dart left out has a smaller one with the
/// same score that is kept. The vertex orbit is walked once, corner by corner, with no list.
/// O(vertex orbit).
fn start_face(body: &Body, start: DartId, direction: Vec3) -> Result<Option<DartId>, CutError> {
    let map = body.map();
    let mut best: Option<(DartId, f64)> = None;
    let mut bad: Option<DartId> = None;
    map.for_each_corner(start, |_, x| {
        // α1 is computed for tets as built (`alpha_local`): only α3(x) reads a row here.
        if x > map.alpha_local(1, x) {
            return;
        }
        let a3 = map.alpha::<3>(x);
        if a3 == x || x > a3 || x > map.alpha_local(1, a3) {
            return;
        }
        let score = dot(face_normal_at(body, x), direction).abs();
        if !score.is_finite() {
            // A NaN normal would win every comparison (`total_cmp`): refused below.
            bad = bad.or(Some(x));
            return;
        }
        if best.is_none_or(|(d, s)| score.total_cmp(&s).then(d.cmp(&x)).is_gt()) {
            best = Some((x, score));
        }
    });
    match bad.and_then(|x| nonfinite_corner(body, x)) {
        Some(e) => Err(e),
        None => Ok(best.map(|(d, _)| d)),
    }
}

/// [`CutError::NonFinitePosition`] for a vertex of the face of `x` (its darts' vertex ids)
/// whose position is NaN or infinite, if there is one. O(face).
fn nonfinite_corner(body: &Body, x: DartId) -> Option<CutError> {
    let (map, pos) = (body.map(), body.attrs().position());
    let vertex = map
        .orbit(x, AlphaMask::of(&[0, 1]))
        .into_iter()
        .map(|d| map.vertex_id(d))
        .filter(|&v| !pos[v].iter().all(|c| c.is_finite()))
        .min()?;
    Some(CutError::NonFinitePosition { vertex, position: pos[vertex] })
}

/// Tears vertex `v` along `direction`: among the inner faces around v, the one whose normal is
/// closest to ±`direction` starts the fan ([`fan_darts`]); every inner face of the fan is then
/// dissociated. `v` is a vertex id; `hint`, when given and still on v, saves the O(darts) search.
/// Only the direction counts, not its length: the direction scaled by any power of two (down to
/// a subnormal, up to near `f64::MAX`) chooses the same face, as the face scores are formed from
/// it scaled to a largest component in [1, 2).
///
/// Cost: O(star of v) to choose the face and walk the fan, plus one dissociation per fan face.
///
/// # Errors
/// [`CutError::NoSuchVertex`] (no live dart carries `v`; body unchanged);
/// [`CutError::BadDirection`] for a non-finite or zero direction;
/// [`CutError::NonFinitePosition`] for a NaN or infinite position on a face around `v` (body
/// unchanged); [`CutError::Body`] is a bug. A vertex with no inner face is left as is (an empty
/// fan).
///
/// # Examples
///
/// ```
/// use topomech::cut::tear_vertex;
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{check_conservation, Body, Material};
/// use topomech::CellId;
///
/// // Tear the centre vertex (1, 1, 1) of the 2×2×2 cube across the x axis.
/// let (points, tets) = kuhn_cube(2);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let tear = tear_vertex(&mut body, CellId(13), [1.0, 0.0, 0.0], None).unwrap();
/// assert!(tear.split && !tear.fan.is_empty());
/// assert!(body.map().count_cells().0[0] > 27);
/// check_conservation(body.map(), body.attrs()).unwrap();
/// ```
pub fn tear_vertex(body: &mut Body, v: CellId, direction: Vec3, hint: Option<DartId>) -> Result<Tear, CutError> {
    if direction.iter().any(|c| !c.is_finite()) || direction == [0.0; 3] {
        return Err(CutError::BadDirection(direction));
    }
    let map = body.map();
    let on_v = |d: DartId| map.contains(d) && map.vertex_id(d) == v;
    let start = hint.filter(|&d| on_v(d)).or_else(|| map.darts().find(|&d| on_v(d)));
    let start = start.ok_or(CutError::NoSuchVertex(v))?;
    // Scaled by a power of two (exact) to a largest component in [1, 2): the scores neither
    // underflow for a tiny direction nor overflow for a huge one, and keep their order.
    let best = start_face(body, start, Scaled::new(direction, 0, 0).dir)?;
    let mut tear =
        Tear { vertex: v, fan: Vec::new(), dissociations: Vec::new(), split: false, touched: TouchedCells::default() };
    let from = body.version();
    let Some(d0) = best else {
        tear.touched.cover(body, from);
        return Ok(tear);
    };
    tear.fan = fan_darts(body.map(), d0);
    tear.dissociations.reserve(tear.fan.len());
    for &d in &tear.fan {
        if body.map().is_free(3, d) {
            continue;
        }
        let dis = dissociate_face(body, d)?;
        tear.split |= dis.vertices.iter().any(|s| s.kept == v);
        tear.touched.extend(&dis.touched);
        tear.dissociations.push(dis);
    }
    tear.touched.cover(body, from);
    Ok(tear)
}

/// One tearing pass inside a simulation loop: computes [`principal_stress`], tears the vertices
/// whose stress exceeds `threshold`, strongest first (at most `max_vertices`; a vertex already
/// split this pass is skipped), then lets `sim` follow the changes ([`Simulation::update`]).
///
/// Cost: O(springs + slots) for the stresses, plus the tears and the update.
///
/// # Errors
/// [`CutError::BadThreshold`] for a NaN, infinite or negative threshold, and
/// [`CutError::Sim`] with [`crate::mechanics::SimError::OtherBody`] when `sim` was built for
/// another body or [`crate::mechanics::SimError::StaleProjection`] when the body changed since
/// `sim` last followed it (nothing done in these cases); [`CutError::Body`] or [`CutError::Sim`]
/// (bugs). The state is not read by the update ([`Simulation::update`]): a NaN or infinite
/// position or velocity, or an energy that overflows, is refused by the next step, with nothing
/// changed, until it is repaired.
///
/// # Examples
///
/// ```
/// use topomech::cut::{tear_step, CutError};
/// use topomech::generate::kuhn_cube;
/// use topomech::mechanics::{Body, Integrator, Material, SimError, Simulation, StepConfig};
///
/// let (points, tets) = kuhn_cube(2);
/// let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
/// let mut sim = Simulation::new(&mut body, [0.0; 3], StepConfig::new(Integrator::Euler, 1e-4)).unwrap();
/// assert!(tear_step(&mut body, &mut sim, 1.0, 4).unwrap().tears.is_empty()); // no tension at rest
/// body.attrs_mut().position_mut().as_mut_slice()[13][0] += 0.5; // stretch the centre vertex
/// let step = tear_step(&mut body, &mut sim, 1.0, 1).unwrap();
/// assert_eq!(step.tears.len(), 1);
/// sim.step(&mut body).unwrap(); // the simulation followed the change
/// assert!(matches!(tear_step(&mut body, &mut sim, f64::NAN, 1), Err(CutError::BadThreshold(_))));
/// let mut copy = body.clone(); // another body: refused before anything tears
/// assert!(matches!(tear_step(&mut copy, &mut sim, 0.0, 1), Err(CutError::Sim(SimError::OtherBody { .. }))));
/// ```
pub fn tear_step(
    body: &mut Body,
    sim: &mut Simulation,
    threshold: f64,
    max_vertices: usize,
) -> Result<TearStep, CutError> {
    if !(threshold.is_finite() && threshold >= 0.0) {
        return Err(CutError::BadThreshold(threshold));
    }
    let stress = principal_stress(body, sim)?;
    let mut order: Vec<usize> = (0..stress.len()).filter(|&v| stress[v].magnitude > threshold).collect();
    order.sort_by(|&a, &b| stress[b].magnitude.total_cmp(&stress[a].magnitude).then(a.cmp(&b)));
    let mut out = TearStep::default();
    let mut touched = TouchedCells::default();
    for v in order.into_iter().take(max_vertices) {
        let id = CellId(v as u32);
        let Some(hint) = sim.projection.dart_of_vertex(v) else { continue };
        if touched.vertices.iter().any(|&(t, _)| t == id) {
            continue;
        }
        let tear = tear_vertex(body, id, stress[v].direction, Some(hint))?;
        touched.extend(&tear.touched);
        out.tears.push(tear);
    }
    if !touched.is_empty() {
        sim.update(body, &touched)?;
    }
    Ok(out)
}

fn mul(m: &[[f64; 3]; 3], v: Vec3) -> Vec3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cut::ops::jittered_cube;
    use crate::mechanics::Material;

    /// The start face is the one the full scan (every inner dart of the vertex scored, highest
    /// score then smallest dart) picks, also with exact ties (the unjittered cube) and after cuts.
    #[test]
    fn start_face_is_the_full_scan_choice() {
        let dirs = [[1.0, 0.0, 0.0], [0.3, -0.7, 0.2], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
        for (seed, jitter) in [(3, true), (0, false)] {
            let (points, tets) = if jitter { jittered_cube(3, seed) } else { crate::generate::kuhn_cube(3) };
            let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
            let some: Vec<DartId> = body.map().darts().filter(|d| d.0 % 97 == 0).collect();
            for d in some {
                if !body.map().is_free(3, d) {
                    dissociate_face(&mut body, d).unwrap();
                }
            }
            let map = body.map();
            let mut checked = 0;
            for start in map.one_dart_per_cell(0) {
                for dir in dirs {
                    let full = map.cell_darts(0, start).into_iter().filter(|&d| !map.is_free(3, d)).max_by(|&a, &b| {
                        let score = |d| dot(face_normal(&body, d), dir).abs();
                        score(a).total_cmp(&score(b)).then(b.cmp(&a))
                    });
                    let mut copy = body.clone();
                    let tear = tear_vertex(&mut copy, map.vertex_id(start), dir, Some(start)).unwrap();
                    assert_eq!(tear.fan.first().copied(), full, "vertex {} direction {dir:?}", map.vertex_id(start));
                    checked += usize::from(full.is_some());
                }
            }
            assert!(checked > 100);
        }
    }

    /// The start face's normal is the geometric one: the star of the centre vertex of the
    /// 2×2×2 Kuhn cube holds faces in the three axis planes through it, and for a direction
    /// along an axis the fan must start on a face of the plane normal to it (checked on the
    /// face's corner positions, not with the code's own normals, which the test above uses on
    /// both sides).
    #[test]
    fn the_fan_starts_on_a_face_normal_to_the_direction() {
        let (points, tets) = crate::generate::kuhn_cube(2);
        let (body, _) = Body::from_tets(&points, &tets, Material::default()).unwrap();
        let (map, position) = (body.map(), &body.attrs().position);
        let centre = map.darts().find(|&d| position[map.vertex_id(d)] == [1.0; 3]).unwrap();
        for axis in 0..3 {
            let mut direction = [0.0; 3];
            direction[axis] = 1.0;
            let mut copy = body.clone();
            let tear = tear_vertex(&mut copy, map.vertex_id(centre), direction, Some(centre)).unwrap();
            let corners = triangle_vertices(map, tear.fan[0]).unwrap().map(|v| position[v]);
            assert!(corners.iter().all(|p| p[axis] == 1.0), "axis {axis}: first fan face {corners:?}");
        }
    }
}
