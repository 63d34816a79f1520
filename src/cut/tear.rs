//! Tearing (seed §5.1, Fig. 10): split a vertex whose inner stress is too high by dissociating the
//! closed fan of faces around it, starting from the face whose normal best matches the stress.
//!
//! The fan walk from a dart d0 of the start face at vertex v: d_{k+1} = α1 α2 α3 α2 (d_k) (apply
//! α2, then α3, α2, α1). α2 turns to the other face of the tet on the current edge, α3 crosses into
//! the neighbouring tet, α2 turns to the other face of that tet on the same edge, α1 moves to the
//! other edge of that face at v. No α0 is used, so every dart stays on v. The walk stops when it
//! comes back to d0, or before an α3 that is free (the surface); in that case it starts again from
//! α1(d0) to collect the other half of the fan.
//!
//! d0 is "one of the two darts belonging to both face and vertex orbits" (seed §5.1) — four
//! darts in fact, two per tet at the face, and the walks from the two tets give different fans.
//! It is chosen by the geometry, not by dart numbering (finding 215): the tet on the side of the
//! start face that the direction points into (exact orientation signs; the direction signed as
//! [`Stress::direction`] is, largest component positive, so ±direction tear alike), and in it
//! the dart whose edge leads to the lexicographically smaller corner; exact ties of the face
//! scores go to the lexicographically smallest corner positions. So the same geometry tears the
//! same faces whatever the order of the tet list.

use std::cmp::Ordering;

use crate::mechanics::geom::{self, cross, dot, sub};
use crate::mechanics::model::{closed_triangle_vertices, triangle_vertices};
use crate::mechanics::{Body, SimError, Simulation, TouchedCells, Vec3};
use crate::{CellId, DartId, GMap};

use super::{dissociate_face, CutError, Dissociation};
use crate::exact::{det_sign, Term};
use crate::mechanics::geom::Scaled;

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
    /// The largest eigenvalue of σ_v (a force: the "inner force" compared with the threshold),
    /// to O(ε ‖σ_v‖); NaN when σ_v is not finite (a NaN or infinite position at v or a
    /// neighbour), which no threshold passes.
    pub magnitude: f64,
    /// Its unit eigenvector, sign chosen so that its largest component is positive (zero when
    /// σ_v is zero). With a repeated largest eigenvalue, a deterministic unit vector of its
    /// eigenspace.
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
    /// One entry per vertex whose tear dissociated faces (empty tears are not listed).
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
        let (xa, xb) = (x[a as usize], x[b as usize]);
        // The length measured as rest lengths are (scale-safe beyond ordinary extents) and the
        // unit direction first: T nᵢ nⱼ over- or underflows only when the stress does (finding
        // 178: T dᵢ dⱼ / l² overflowed for a body of edges near 1e80, underflowed near 1e-90).
        let l = geom::rest_length(xa, xb);
        let tension = sys.stiffness[s] * (l - sys.rest[s]);
        if l == 0.0 || tension <= 0.0 {
            continue;
        }
        let n = sub(xb, xa).map(|c| c / l);
        for v in [a, b] {
            for (i, row) in sigma[v as usize].iter_mut().enumerate() {
                for (j, e) in row.iter_mut().enumerate() {
                    *e += tension * n[i] * n[j];
                }
            }
        }
    }
    Ok(sigma.iter().map(largest_eigenpair).collect())
}

/// Largest eigenpair of a symmetric 3×3 matrix (its upper triangle is read) by cyclic Jacobi
/// rotations to convergence. O(1): a few sweeps of three rotations, at most [`JACOBI_SWEEPS`].
///
/// The power iteration used before (finding 172) started from the largest column and never left
/// it when that column was an eigenvector of a smaller eigenvalue (exact zeros, as on Kuhn cubes).
/// Jacobi has no start vector: the diagonal it converges to holds every eigenvalue, to
/// O(ε ‖m‖), and the rotations' product the eigenvectors, orthonormal to O(ε). A diagonal
/// matrix is returned exactly (no rotation). The largest diagonal entry wins, the lowest index
/// on exact ties (repeated eigenvalues: any unit vector of the eigenspace is right, this one is
/// deterministic); its vector is normalised and signed so that its largest component (lowest
/// index on ties) is positive. No randomness, no 0/0: m = 0 gives magnitude 0 and the zero
/// direction ([`Stress::direction`]); a NaN or infinite entry gives NaN (never above a
/// threshold).
fn largest_eigenpair(m: &[[f64; 3]; 3]) -> Stress {
    let mut a = [[m[0][0], m[0][1], m[0][2]], [m[0][1], m[1][1], m[1][2]], [m[0][2], m[1][2], m[2][2]]];
    if a.iter().flatten().any(|e| !e.is_finite()) {
        return Stress { magnitude: f64::NAN, direction: [f64::NAN; 3] };
    }
    if a.iter().flatten().all(|&e| e == 0.0) {
        return Stress { magnitude: 0.0, direction: [0.0; 3] };
    }
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]; // columns: eigenvectors
    for _ in 0..JACOBI_SWEEPS {
        let mut rotated = false;
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            rotated |= jacobi_rotate(&mut a, &mut v, p, q);
        }
        if !rotated {
            break;
        }
    }
    let k = (1..3).fold(0, |k, i| if a[i][i] > a[k][k] { i } else { k });
    let mut x = [v[0][k], v[1][k], v[2][k]];
    let big = (1..3).fold(0, |b, i| if x[i].abs() > x[b].abs() { i } else { b });
    // |x| = 1 to O(ε) (a product of rotations): the division is safe.
    let n = dot(x, x).sqrt().copysign(x[big]);
    x = [x[0] / n, x[1] / n, x[2] / n];
    Stress { magnitude: a[k][k], direction: x }
}

/// One Jacobi rotation of the symmetric `a` in the (p, q) plane that zeroes a[p][q], applied to
/// the eigenvector columns `v` too; returns whether it rotated. An a[p][q] of 0, or negligible
/// against both diagonal entries (dropping it moves the eigenvalues by less than 1e-2 ulp of
/// them, Numerical Recipes' `jacobi` test), is set to 0 with no rotation. O(1).
fn jacobi_rotate(a: &mut [[f64; 3]; 3], v: &mut [[f64; 3]; 3], p: usize, q: usize) -> bool {
    let apq = a[p][q];
    if apq == 0.0 {
        return false;
    }
    let g = 100.0 * apq.abs();
    if a[p][p].abs() + g == a[p][p].abs() && a[q][q].abs() + g == a[q][q].abs() {
        a[p][q] = 0.0;
        a[q][p] = 0.0;
        return false;
    }
    // The rotation that zeroes a[p][q] (Golub & Van Loan, sym.schur2), the smaller angle:
    // t = tan φ = sign(θ) / (|θ| + √(θ² + 1)), θ = (a_qq − a_pp) / (2 a_pq). θ may be
    // infinite (a tiny a_pq): t = 0, no change; θ² overflowing gives t = 0 too.
    let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
    let t =
        if theta.abs() > 1e150 { 0.5 / theta } else { theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt()) };
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    a[p][p] -= t * apq;
    a[q][q] += t * apq;
    a[p][q] = 0.0;
    a[q][p] = 0.0;
    let r = 3 - p - q;
    let (arp, arq) = (a[r][p], a[r][q]);
    a[r][p] = c * arp - s * arq;
    a[p][r] = a[r][p];
    a[r][q] = s * arp + c * arq;
    a[q][r] = a[r][q];
    for row in v.iter_mut() {
        let (vp, vq) = (row[p], row[q]);
        row[p] = c * vp - s * vq;
        row[q] = s * vp + c * vq;
    }
    true
}

/// Sweeps of [`largest_eigenpair`] at most. Jacobi converges quadratically: 3×3 matrices need
/// 3 to 6 sweeps to reach zero (or negligible) off-diagonal entries.
const JACOBI_SWEEPS: usize = 32;

/// One dart per face of the fan around the vertex of `d0`, starting with `d0`'s face, in walk
/// order (module docs). Faces met twice are listed once. Every walk is bounded by the dart count.
/// O(fan) expected (the faces seen are a short list, then a hash set past 64 faces: finding 303,
/// a list scanned per face was quadratic at high valence). Empty when `d0` is not a
/// live dart.
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
    let mut faces = FacesSeen::default();
    let mut out = Vec::with_capacity(16);
    let mut push = |d: DartId, out: &mut Vec<DartId>| {
        if faces.insert(map.cell_id(2, d)) {
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

/// Faces a fan walk has seen past which [`FacesSeen`] leaves its list for a hash set: a fan
/// around an ordinary vertex has 10–40 faces, which a scan of a short list handles fastest.
const FACES_SCANNED: usize = 64;

/// The set of faces a fan walk has seen: a list scanned linearly while short, a hash set past
/// [`FACES_SCANNED`] entries. O(1) expected per insertion.
#[derive(Default)]
struct FacesSeen {
    list: Vec<CellId>,
    set: std::collections::HashSet<CellId>,
}

impl FacesSeen {
    /// Adds `f`; whether it was new.
    fn insert(&mut self, f: CellId) -> bool {
        if !self.set.is_empty() {
            return self.set.insert(f);
        }
        if self.list.contains(&f) {
            return false;
        }
        self.list.push(f);
        if self.list.len() > FACES_SCANNED {
            self.set.extend(self.list.drain(..));
        }
        true
    }
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

/// Unit normal (up to sign) of the triangle with vertex ids `[a, b, c]` from current positions
/// (zero if degenerate). The corners are taken in lexicographic order of their positions, so the
/// rounding of the normal depends on the geometry, never on the numbering (finding 220). O(1).
fn triangle_normal(body: &Body, ids: [CellId; 3]) -> Vec3 {
    let mech = body.attrs();
    let mut p = ids.map(|v| mech.position[v]);
    p.sort_by(|x, y| cmp_points(std::slice::from_ref(x), std::slice::from_ref(y)));
    // The edges and their cross product scaled by powers of two to a largest component in
    // [1, 2) (exact): no overflow or underflow at any coordinate scale (finding 85). For ordinary
    // coordinates the unit normal is the unscaled one bit for bit.
    let (e1, e2) = (Scaled::diff(p[1], p[0], 0).dir, Scaled::diff(p[2], p[0], 0).dir);
    let n = Scaled::new(cross(e1, e2), 0).dir;
    let len = dot(n, n).sqrt();
    if len == 0.0 {
        return [0.0; 3];
    }
    [n[0] / len, n[1] / len, n[2] / len]
}

/// Unit normal of the face of `d` from current positions (zero if it is not a triangle with
/// three distinct vertices, or degenerate). O(face). The unit tests' reference.
#[cfg(test)]
fn face_normal(body: &Body, d: DartId) -> Vec3 {
    triangle_vertices(body.map(), d).map_or([0.0; 3], |t| triangle_normal(body, t))
}

/// The unit normal of the face of `x` (a dart of the vertex being torn; zero if the face has not
/// three distinct vertices, or is degenerate), reading the face's vertices off
/// three darts instead of walking its orbit: when the face ⟨α0, α1⟩(x) closes after six darts
/// (x, α0 x, α1 α0 x, α0 α1 α0 x = α1 α0 α1 x, α0 α1 x, α1 x) its vertices are those of x,
/// α0 x and α0 α1 x ([`closed_triangle_vertices`]); if they are distinct, that is
/// [`triangle_vertices`]' sorted triple and the normal is the same bit for bit. Otherwise falls
/// back to walking the face ([`triangle_vertices`]). O(1).
fn face_normal_at(body: &Body, x: DartId) -> Vec3 {
    face_vertices_at(body, x).map_or([0.0; 3], |t| triangle_normal(body, t))
}

/// The sorted vertex ids of the face of `x` (a dart of the vertex being torn) as
/// [`face_normal_at`] reads them: three ids off three darts when the face closes as a hexagon,
/// else [`triangle_vertices`]; `None` when it has not three distinct vertices. O(1) (O(face)
/// in the fallback).
fn face_vertices_at(body: &Body, x: DartId) -> Option<[CellId; 3]> {
    let map = body.map();
    // A face of a tet as built is a closed hexagon (the layout law), so the test is skipped then.
    let closed = map.tets_as_built() || {
        let (a, b) = (map.alpha_local(0, x), map.alpha_local(1, x));
        let c = map.alpha_local(0, b);
        a != x && b != x && c != b && map.alpha_local(0, map.alpha_local(1, a)) == map.alpha_local(1, c)
    };
    match closed.then(|| closed_triangle_vertices(map, x)).flatten() {
        Some(ids) => Some(ids),
        None => triangle_vertices(map, x),
    }
}

/// The start face of the fan of the vertex of `start`, as its smallest dart at the vertex: among
/// the inner faces at the vertex, the one whose normal is closest to ±`direction` (highest
/// |n · direction|); on an exact tie of scores, the face whose corner positions, sorted
/// lexicographically, are lexicographically smallest (a geometric rule: the same face whatever
/// the numbering of the darts, i.e. the order of the tets); the smallest dart only between
/// faces with the same three corner positions (coincident vertices). `None` if every face at
/// the vertex is on the boundary.
///
/// A face's score depends only on its vertices, shared by x, α1(x), α3(x), α1α3(x): only the
/// smallest of the four is scored, with the O(1) normal of [`face_normal_at`]. The choice is
/// that of scoring every inner dart (unit test). Which of the two tets at the face the fan starts
/// from is [`start_side`]'s choice. The vertex orbit is walked once, corner by corner, with no
/// list. O(vertex orbit).
///
/// # Errors
/// [`CutError::NonFinitePosition`] for the smallest vertex id of the star (the vertex and the
/// other end of every edge at it: the corners of every face and tet around it, boundary faces
/// included) whose position is NaN or infinite (finding 289: a NaN on a boundary face only was
/// read by [`start_side`] as a tie).
fn start_face(body: &Body, start: DartId, direction: Vec3) -> Result<Option<DartId>, CutError> {
    let (map, pos) = (body.map(), body.attrs().position());
    let mut best: Option<(DartId, f64)> = None;
    let mut bad: Option<CellId> = None;
    let mut note = |w: CellId| {
        if !pos[w].iter().all(|c| c.is_finite()) && bad.is_none_or(|b| w < b) {
            bad = Some(w);
        }
    };
    note(map.vertex_id(start));
    map.for_each_corner(start, |_, x| {
        note(map.vertex_id(map.alpha_local(0, x)));
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
            // A NaN normal would win every comparison (`total_cmp`); its corners are refused
            // above, and a face of finite corners whose normal overflowed is not a candidate.
            return;
        }
        let better = |(d, s): (DartId, f64)| match score.total_cmp(&s) {
            Ordering::Equal => cmp_points(&face_key(body, x), &face_key(body, d)).then(x.cmp(&d)).is_lt(),
            order => order.is_gt(),
        };
        if best.is_none_or(better) {
            best = Some((x, score));
        }
    });
    match bad {
        Some(vertex) => Err(CutError::NonFinitePosition { vertex, position: pos[vertex] }),
        None => Ok(best.map(|(d, _)| d)),
    }
}

/// The corner positions of the face of `x`, sorted lexicographically ([`cmp_points`]); all
/// three the vertex's own position when the face has not three distinct vertices. O(1).
fn face_key(body: &Body, x: DartId) -> [Vec3; 3] {
    let pos = body.attrs().position();
    let mut key = match face_vertices_at(body, x) {
        Some(ids) => ids.map(|v| pos[v]),
        None => [pos[body.map().vertex_id(x)]; 3],
    };
    key.sort_by(|a, b| cmp_points(std::slice::from_ref(a), std::slice::from_ref(b)));
    key
}

/// Lexicographic order of point lists, coordinate by coordinate ([`f64::total_cmp`]). O(len).
fn cmp_points(a: &[Vec3], b: &[Vec3]) -> Ordering {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| x.total_cmp(y))
        .find(|o| o.is_ne())
        .unwrap_or(Ordering::Equal)
}

/// The dart d0 the fan walk starts from, given an inner dart `x` of the start face at the
/// vertex: the side is chosen by the geometry, never by dart numbering.
///
/// - The tet: of the two tets at the face (that of `x` and that of α3 x), the one lying on the
///   side of the face's plane that `direction` points into, `direction` taken with the sign
///   convention of [`Stress::direction`] (its largest component positive, the lowest index on
///   ties), so that ±`direction` tear alike, as they choose the same face: with f₀, f₁, f₂ the face's corners
///   and c a tet's fourth corner, the tet whose sign of det[f₁ − f₀, f₂ − f₀, c − f₀] is that of
///   det[f₁ − f₀, f₂ − f₀, direction] (both signs exact, [`det_sign`]; the product does not depend
///   on the order of the corners). On a tie (a direction in the face's plane, a flat or inverted
///   tet, a non-finite position) the tet whose fourth corner is lexicographically smaller
///   ([`cmp_points`]); only coincident fourth corners fall back to the smaller dart.
/// - In that tet, of the two darts at the vertex on the face (on its two edges there), the one
///   whose edge's other end is lexicographically smaller (the same fan either way: the walks
///   from d0 and α1 d0 visit the same faces; this fixes the walk order); coincident ends fall
///   back to the smaller dart.
///
/// O(1).
fn start_side(body: &Body, x: DartId, direction: Vec3) -> DartId {
    let (map, pos) = (body.map(), body.attrs().position());
    // ±direction alike: the sign convention of `Stress::direction`.
    let big = (1..3).fold(0, |b, i| if direction[i].abs() > direction[b].abs() { i } else { b });
    let direction = if direction[big] < 0.0 { direction.map(|c| -c) } else { direction };
    let y = map.alpha::<3>(x);
    let at = |d: DartId| pos[map.vertex_id(d)];
    let fourth = |d: DartId| at(map.alpha::<0>(map.alpha::<1>(map.alpha::<2>(d))));
    let (cx, cy) = (fourth(x), fourth(y));
    let into = |c: Vec3| -> i8 {
        let Some([f0, f1, f2]) = face_vertices_at(body, x).map(|t| t.map(|v| pos[v])) else { return 0 };
        let (e1, e2): (&[Term], &[Term]) = (&[(false, f1), (true, f0)], &[(false, f2), (true, f0)]);
        match (det_sign([e1, e2, &[(false, c), (true, f0)]]), det_sign([e1, e2, &[(false, direction)]])) {
            (Some(g), Some(h)) => g as i8 * h as i8,
            _ => 0,
        }
    };
    let tet = match into(cx).cmp(&into(cy)).then_with(|| cmp_points(&[cy], &[cx])).then(y.cmp(&x)) {
        Ordering::Less => y,
        _ => x,
    };
    let other = map.alpha::<1>(tet);
    match cmp_points(&[at(map.alpha::<0>(tet))], &[at(map.alpha::<0>(other))]).then(tet.cmp(&other)) {
        Ordering::Greater => other,
        _ => tet,
    }
}

/// Tears vertex `v` along `direction`: among the inner faces around v, the one whose normal is
/// closest to ±`direction` starts the fan ([`fan_darts`]), walked from the tet at that face on
/// the side `direction` points into (module docs: the start face's ties and the side are decided
/// by positions, so the faces torn do not depend on the order of the tet list); every inner face
/// of the fan is then dissociated. `v` is a vertex id; `hint`, when given and still on v, saves the O(darts) search.
/// Only the direction counts, not its length: the direction scaled by any power of two (down to
/// a subnormal, up to near `f64::MAX`) chooses the same face, as the face scores are formed from
/// it scaled to a largest component in [1, 2).
///
/// Cost: O(star of v) to choose the face and walk the fan, plus one dissociation per fan face.
///
/// # Errors
/// [`CutError::NoSuchVertex`] (no live dart carries `v`; body unchanged);
/// [`CutError::BadDirection`] for a non-finite or zero direction;
/// [`CutError::NonFinitePosition`] for a NaN or infinite position on a face around `v`, boundary
/// faces included (the smallest such vertex id; body unchanged, also when v has no inner face);
/// [`CutError::Body`] is a bug. A vertex with no inner face is left as is (an empty
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
    let best = start_face(body, start, Scaled::new(direction, 0).dir)?.map(|x| start_side(body, x, direction));
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

/// Refuses a tear threshold that is NaN, infinite or negative ([`CutError::BadThreshold`]: with
/// NaN no stress would ever compare above it and tearing would silently never happen), as
/// [`tear_step`] does before anything; a caller that steps before its first tear (the CLI's
/// `tear`) checks it up front with this. O(1).
///
/// # Examples
///
/// ```
/// use topomech::cut::{check_threshold, CutError};
/// assert!(check_threshold(2.5).is_ok() && check_threshold(0.0).is_ok());
/// assert!(matches!(check_threshold(f64::NAN), Err(CutError::BadThreshold(_))));
/// assert!(matches!(check_threshold(-1.0), Err(CutError::BadThreshold(_))));
/// ```
pub fn check_threshold(threshold: f64) -> Result<(), CutError> {
    if threshold.is_finite() && threshold >= 0.0 {
        return Ok(());
    }
    Err(CutError::BadThreshold(threshold))
}

/// One tearing pass inside a simulation loop: computes [`principal_stress`], tears the vertices
/// whose stress exceeds `threshold`, strongest first, until `max_vertices` tears dissociated
/// something (a vertex already touched by a tear of this pass is skipped; a vertex with no inner
/// face, whose tear would be empty, is passed over without spending the budget: round 25, the
/// fragments of a torn body had starved every tearable vertex), then lets `sim` follow the
/// changes ([`Simulation::update`]). [`TearStep::tears`] lists the tears that dissociated faces.
///
/// Cost: O(springs + slots) for the stresses, plus the tears tried (each O(vertex star) when
/// empty) and the update.
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
    check_threshold(threshold)?;
    let stress = principal_stress(body, sim)?;
    let mut order: Vec<usize> = (0..stress.len()).filter(|&v| stress[v].magnitude > threshold).collect();
    order.sort_by(|&a, &b| stress[b].magnitude.total_cmp(&stress[a].magnitude).then(a.cmp(&b)));
    let mut out = TearStep::default();
    let mut touched = TouchedCells::default();
    // Vertices a tear of this pass touched (their stress is stale): marked, not searched for
    // in the touched list, which would make a pass quadratic in its tears (finding 226).
    let mut stale = vec![false; stress.len()];
    for v in order {
        if out.tears.len() == max_vertices {
            break;
        }
        let Some(hint) = sim.projection.dart_of_vertex(v) else { continue };
        if stale[v] {
            continue;
        }
        let tear = tear_vertex(body, CellId(v as u32), stress[v].direction, Some(hint))?;
        if tear.dissociations.is_empty() {
            continue; // no inner face at v (an empty tear): nothing changed, no budget spent
        }
        for &(t, _) in &tear.touched.vertices {
            if let Some(mark) = stale.get_mut(t.index()) {
                *mark = true;
            }
        }
        touched.extend(&tear.touched);
        out.tears.push(tear);
    }
    if !touched.is_empty() {
        sim.update(body, &touched)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cut::ops::jittered_cube;
    use crate::mechanics::Material;
    use proptest::prelude::*;

    /// The start face is the one the full scan (every inner dart of the vertex scored, highest
    /// score, then the lexicographically smallest sorted corner positions, then the smallest
    /// dart) picks, also with exact ties (the unjittered cube) and after cuts; the fan starts
    /// on that face.
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
                    let key = |d: DartId| {
                        let mut k = triangle_vertices(map, d).unwrap().map(|v| body.attrs().position[v]);
                        k.sort_by(|a, b| {
                            a.iter().zip(b).map(|(x, y)| x.total_cmp(y)).find(|o| o.is_ne()).unwrap_or(Ordering::Equal)
                        });
                        k
                    };
                    let full = map.cell_darts(0, start).into_iter().filter(|&d| !map.is_free(3, d)).max_by(|&a, &b| {
                        let score = |d| dot(face_normal(&body, d), dir).abs();
                        score(a).total_cmp(&score(b)).then_with(|| cmp_points(&key(b), &key(a))).then(b.cmp(&a))
                    });
                    let mut copy = body.clone();
                    let tear = tear_vertex(&mut copy, map.vertex_id(start), dir, Some(start)).unwrap();
                    let face = |d: Option<DartId>| d.map(|d| map.cell_id(2, d));
                    assert_eq!(
                        face(tear.fan.first().copied()),
                        face(full),
                        "vertex {} direction {dir:?}",
                        map.vertex_id(start)
                    );
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
    fn mat_vec(m: &[[f64; 3]; 3], v: Vec3) -> Vec3 {
        [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
    }

    /// σ = Σ T n nᵀ over (T, d) with n = d / |d|, formed as `principal_stress` forms it.
    fn sigma_of(springs: &[(f64, Vec3)]) -> [[f64; 3]; 3] {
        let mut m = [[0.0; 3]; 3];
        for &(t, d) in springs {
            let l2 = dot(d, d);
            for (i, row) in m.iter_mut().enumerate() {
                for (j, e) in row.iter_mut().enumerate() {
                    *e += t * d[i] * d[j] / l2;
                }
            }
        }
        m
    }

    /// The independent check of finding 172: |v| = 1, ‖σv − λv‖ ≤ 1e-12 ‖σ‖ (λ is an eigenvalue,
    /// v its vector) and λ ≥ xᵀσx / xᵀx − 1e-12 ‖σ‖ for every x given (λ is the largest), and
    /// the same bits on a second call.
    fn check_largest(m: &[[f64; 3]; 3], probes: &[Vec3]) -> Stress {
        let s = largest_eigenpair(m);
        assert_eq!(format!("{s:?}"), format!("{:?}", largest_eigenpair(m)), "deterministic");
        let norm = m.iter().flatten().map(|e| e * e).sum::<f64>().sqrt();
        let (l, v) = (s.magnitude, s.direction);
        assert!((dot(v, v).sqrt() - 1.0).abs() <= 1e-14, "{m:?}: |v| = {}", dot(v, v).sqrt());
        let r = sub(mat_vec(m, v), [l * v[0], l * v[1], l * v[2]]);
        assert!(dot(r, r).sqrt() <= 1e-12 * norm, "{m:?}: residual {:e}, λ {l}, v {v:?}", dot(r, r).sqrt());
        let mut all = vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        all.extend((0..3).map(|j| [m[0][j], m[1][j], m[2][j]]));
        all.extend_from_slice(probes);
        for x in all.into_iter().filter(|x| dot(*x, *x) > 0.0) {
            let q = dot(x, mat_vec(m, x)) / dot(x, x);
            assert!(l >= q - 1e-12 * norm, "{m:?}: λ {l} < Rayleigh quotient {q} along {x:?}");
        }
        s
    }

    /// Directions with exact zeros, as on Kuhn cubes and boxes: axes, face and body diagonals.
    fn lattice() -> impl Strategy<Value = Vec3> {
        (0usize..13, any::<bool>()).prop_map(|(i, flip)| {
            let d = [
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [1.0, 1.0, 0.0],
                [1.0, -1.0, 0.0],
                [1.0, 0.0, 1.0],
                [1.0, 0.0, -1.0],
                [0.0, 1.0, 1.0],
                [0.0, 1.0, -1.0],
                [1.0, 1.0, 1.0],
                [1.0, -1.0, 1.0],
                [1.0, 1.0, -1.0],
                [-1.0, 1.0, 1.0],
            ][i];
            if flip {
                d.map(|c| -c)
            } else {
                d
            }
        })
    }

    fn direction() -> impl Strategy<Value = Vec3> {
        prop_oneof![
            lattice(),
            [-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0].prop_filter("non-zero", |d| dot(*d, *d) > 1e-6),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        /// Finding 172: for σ = Σ T n nᵀ (1 to 6 springs, tensions over 12 orders of magnitude,
        /// lattice or random directions) the pair is the largest eigenvalue and a unit vector of
        /// it. The power iteration failed this on lattice directions (it returned the second
        /// eigenpair whenever the largest column was an eigenvector of a smaller eigenvalue).
        #[test]
        fn largest_eigenpair_is_the_largest_for_every_spring_stress(
            springs in proptest::collection::vec((1e-6f64..1e6, direction()), 1..7),
            probes in proptest::collection::vec(direction(), 0..4),
        ) {
            let m = sigma_of(&springs);
            let mut probes = probes;
            probes.extend(springs.iter().map(|&(_, d)| d));
            let s = check_largest(&m, &probes);
            let trace = m[0][0] + m[1][1] + m[2][2];
            prop_assert!(s.magnitude > 0.0 && s.magnitude <= trace * (1.0 + 1e-12));
        }
    }

    /// Exact structured cases: a diagonal matrix gives its largest entry and that axis exactly,
    /// wherever it is; repeated eigenvalues give the lowest axis (diagonal) or a unit vector of
    /// the eigenspace; rank 1 gives its direction; zero gives the documented zero pair; a NaN
    /// entry gives NaN, never a number that could pass a threshold.
    #[test]
    fn largest_eigenpair_exact_structured_cases() {
        for k in 0..3 {
            for (big, small) in [(3.0, [1.0, 2.0]), (1e-300, [0.0, 5e-301]), (7.5, [7.0, 0.0])] {
                let mut m = [[0.0; 3]; 3];
                let mut e = [0.0; 3];
                e[k] = 1.0;
                m[k][k] = big;
                m[(k + 1) % 3][(k + 1) % 3] = small[0];
                m[(k + 2) % 3][(k + 2) % 3] = small[1];
                assert_eq!(largest_eigenpair(&m), Stress { magnitude: big, direction: e }, "{m:?}");
            }
        }
        let diag = |a: f64, b: f64, c: f64| [[a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]];
        assert_eq!(largest_eigenpair(&diag(2.0, 2.0, 1.0)).direction, [1.0, 0.0, 0.0]);
        assert_eq!(largest_eigenpair(&diag(1.0, 2.0, 2.0)).direction, [0.0, 1.0, 0.0]);
        assert_eq!(largest_eigenpair(&diag(4.0, 4.0, 4.0)), Stress { magnitude: 4.0, direction: [1.0, 0.0, 0.0] });
        assert_eq!(largest_eigenpair(&[[0.0; 3]; 3]), Stress { magnitude: 0.0, direction: [0.0; 3] });
        let nan = largest_eigenpair(&diag(1.0, f64::NAN, 0.0));
        assert!(nan.magnitude.is_nan() && nan.direction.iter().all(|c| c.is_nan()));
        assert!(largest_eigenpair(&diag(1.0, f64::INFINITY, 0.0)).magnitude.is_nan());

        let r = std::f64::consts::FRAC_1_SQRT_2;
        // The finding's σ: 5/3 along (1, 1, 0)/√2 and 1.5 along z (largest column (0, 0, 1.5)).
        let s = check_largest(&sigma_of(&[(5.0 / 3.0, [1.0, 1.0, 0.0]), (1.5, [0.0, 0.0, 1.0])]), &[]);
        assert!((s.magnitude - 5.0 / 3.0).abs() <= 1e-15 && (dot(s.direction, [r, r, 0.0]).abs() - 1.0).abs() <= 1e-15);
        // Rank 1 along a body diagonal and along a face diagonal.
        for d in [[1.0, 1.0, 1.0], [0.0, 1.0, -1.0]] {
            let s = check_largest(&sigma_of(&[(2.0, d)]), &[]);
            let n = dot(d, d).sqrt();
            assert!((s.magnitude - 2.0).abs() <= 1e-15 && (dot(s.direction, d).abs() / n - 1.0).abs() <= 1e-15);
        }
        // A double largest eigenvalue with a non-axis eigenspace: 3 on span{(1,1,0), (1,−1,2)}, 1
        // on their normal (−1, 1, 1): the vector is in the span (orthogonal to the normal).
        let m = sigma_of(&[(3.0, [1.0, 1.0, 0.0]), (3.0, [1.0, -1.0, 2.0]), (1.0, [-1.0, 1.0, 1.0])]);
        let s = check_largest(&m, &[[1.0, 1.0, 0.0], [1.0, -1.0, 2.0]]);
        assert!((s.magnitude - 3.0).abs() <= 1e-14 && dot(s.direction, [-1.0, 1.0, 1.0]).abs() <= 1e-14);
        // Off-diagonal entries far below the diagonal's (1e-200 against 1): no underflow, no NaN.
        let tiny = [[1.0, 1e-200, 0.0], [1e-200, 1.0, 1e-200], [0.0, 1e-200, 0.5]];
        assert_eq!(check_largest(&tiny, &[]).magnitude, 1.0);
    }
}
