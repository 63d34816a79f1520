//! Forces of the mass/spring model on plain arrays, and the orbit-walk reference.
//!
//! Forces on a vertex v (all laws in `docs/MECHANICS.md`):
//! - gravity m_v g;
//! - ambient viscosity −γ_v ẋ_v;
//! - each spring s = (a, b) with rest length L, stiffness k, damping c: with d = x_b − x_a,
//!   l = |d|, n = d / l, the force on a is F_s = [k (l − L) + c (ẋ_b − ẋ_a)·n] n and the force on
//!   b is −F_s (Hooke's law plus damping along the spring).
//!
//! [`SpringSystem`] evaluates them in two passes: one over the springs writing F_s into an array,
//! then one over the vertices gathering, through a CSR list of incident springs, the F_s of the
//! springs that start at v minus those that end at v. No two writes go to the same slot, so both
//! passes split freely across threads and the result is bitwise the same for any thread count.

use rayon::prelude::*;

use super::geom::{dot, norm, sub, Vec3};

/// Spring and vertex count above which the parallel passes are worth their overhead.
pub const PARALLEL_CHUNK: usize = 4096;

/// The mass/spring system as flat arrays: what the step loop reads.
///
/// Vertices are *slots* `0..slots()`: positions and velocities are passed in as slices of that
/// length. A slot with `inv_mass == 0` does not move (pinned, dead or massless).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpringSystem {
    /// Spring end slots (a, b).
    pub ends: Vec<[u32; 2]>,
    /// Rest length L of each spring.
    pub rest: Vec<f64>,
    /// Stiffness k of each spring.
    pub stiffness: Vec<f64>,
    /// Damping c of each spring.
    pub damping: Vec<f64>,
    /// Mass of each slot.
    pub mass: Vec<f64>,
    /// 1/m for a free slot, 0 for a fixed one.
    pub inv_mass: Vec<f64>,
    /// Ambient viscosity γ of each slot.
    pub viscosity: Vec<f64>,
    /// Gravity acceleration g.
    pub gravity: Vec3,
    /// CSR of incident springs: for slot v, `adj[off[2v]..off[2v+1]]` are the springs with a = v,
    /// `adj[off[2v+1]..off[2v+2]]` those with b = v.
    off: Vec<u32>,
    adj: Vec<u32>,
}

impl SpringSystem {
    /// A system from its arrays; builds the CSR. O(slots + springs).
    ///
    /// Panics if the arrays disagree in length or an end is out of range (a bug of the builder).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ends: Vec<[u32; 2]>,
        rest: Vec<f64>,
        stiffness: Vec<f64>,
        damping: Vec<f64>,
        mass: Vec<f64>,
        fixed: &[bool],
        viscosity: Vec<f64>,
        gravity: Vec3,
    ) -> Self {
        let n = mass.len();
        assert!(rest.len() == ends.len() && stiffness.len() == ends.len() && damping.len() == ends.len());
        assert!(fixed.len() == n && viscosity.len() == n);
        let inv_mass = mass.iter().zip(fixed).map(|(&m, &f)| if f || m <= 0.0 { 0.0 } else { 1.0 / m }).collect();
        let (off, adj) = incidence(n, &ends);
        SpringSystem { ends, rest, stiffness, damping, mass, inv_mass, viscosity, gravity, off, adj }
    }

    /// Number of vertex slots. O(1).
    pub fn slots(&self) -> usize {
        self.mass.len()
    }

    /// Number of springs. O(1).
    pub fn springs(&self) -> usize {
        self.ends.len()
    }

    /// Pass 1: F_s (force on end a) of every spring into `sf`. O(springs).
    pub fn spring_forces(&self, x: &[Vec3], v: &[Vec3], sf: &mut [Vec3], parallel: bool) {
        if parallel && sf.len() > PARALLEL_CHUNK {
            sf.par_chunks_mut(PARALLEL_CHUNK).enumerate().for_each(|(c, chunk)| {
                self.spring_range(x, v, c * PARALLEL_CHUNK, chunk);
            });
        } else {
            self.spring_range(x, v, 0, sf);
        }
    }

    /// Springs `start..start + out.len()` in blocks of [`BLOCK`]: a scalar gather of the end
    /// states, a branch-free arithmetic loop the compiler vectorises (sqrt and division are the
    /// cost of a spring), then the writes. Same arithmetic as [`spring_force`], bit for bit.
    #[inline]
    fn spring_range(&self, x: &[Vec3], v: &[Vec3], start: usize, out: &mut [Vec3]) {
        for (b, chunk) in out.chunks_mut(BLOCK).enumerate() {
            let first = start + b * BLOCK;
            let n = chunk.len();
            let mut d = [[0.0f64; BLOCK]; 3];
            let mut dv = [[0.0f64; BLOCK]; 3];
            for (j, &[a, bb]) in self.ends[first..first + n].iter().enumerate() {
                let (xa, xb, va, vb) = (x[a as usize], x[bb as usize], v[a as usize], v[bb as usize]);
                for c in 0..3 {
                    d[c][j] = xb[c] - xa[c];
                    dv[c][j] = vb[c] - va[c];
                }
            }
            let mut s = [0.0f64; BLOCK];
            let (rest, k, damp) =
                (&self.rest[first..first + n], &self.stiffness[first..first + n], &self.damping[first..first + n]);
            for j in 0..n {
                s[j] = spring_scale(d[0][j], d[1][j], d[2][j], dv[0][j], dv[1][j], dv[2][j], rest[j], k[j], damp[j]);
            }
            for (j, f) in chunk.iter_mut().enumerate() {
                *f = [s[j] * d[0][j], s[j] * d[1][j], s[j] * d[2][j]];
            }
        }
    }

    /// Σ over incident springs (+F_s where v = a, −F_s where v = b). O(degree).
    #[inline(always)]
    fn gather(&self, i: usize, sf: &[Vec3]) -> Vec3 {
        let (o0, o1, o2) = (self.off[2 * i] as usize, self.off[2 * i + 1] as usize, self.off[2 * i + 2] as usize);
        let mut f = [0.0; 3];
        for &s in &self.adj[o0..o1] {
            let g = sf[s as usize];
            f = [f[0] + g[0], f[1] + g[1], f[2] + g[2]];
        }
        for &s in &self.adj[o1..o2] {
            let g = sf[s as usize];
            f = [f[0] - g[0], f[1] - g[1], f[2] - g[2]];
        }
        f
    }

    /// Total force on slot i from gravity, viscosity and the springs (given F_s in `sf`). O(degree).
    #[inline(always)]
    pub fn vertex_force(&self, i: usize, v: &[Vec3], sf: &[Vec3]) -> Vec3 {
        let s = self.gather(i, sf);
        let (m, g, vi) = (self.mass[i], self.viscosity[i], v[i]);
        [
            s[0] + m * self.gravity[0] - g * vi[0],
            s[1] + m * self.gravity[1] - g * vi[1],
            s[2] + m * self.gravity[2] - g * vi[2],
        ]
    }

    /// Forces on every slot (pinned ones included) into `out`. O(slots + springs).
    pub fn forces(&self, x: &[Vec3], v: &[Vec3], sf: &mut [Vec3], out: &mut [Vec3], parallel: bool) {
        self.spring_forces(x, v, sf, parallel);
        self.per_slot(out, parallel, |i| self.vertex_force(i, v, sf));
    }

    /// Accelerations f_i / m_i (zero on fixed slots) into `acc`. O(slots + springs).
    pub fn accelerations(&self, x: &[Vec3], v: &[Vec3], sf: &mut [Vec3], acc: &mut [Vec3], parallel: bool) {
        self.spring_forces(x, v, sf, parallel);
        let sf: &[Vec3] = sf;
        self.per_slot(acc, parallel, |i| {
            let f = self.vertex_force(i, v, sf);
            let w = self.inv_mass[i];
            [f[0] * w, f[1] * w, f[2] * w]
        });
    }

    /// `out[i] = value(i)` for every slot, split across threads when asked and large.
    #[inline]
    pub(crate) fn per_slot(&self, out: &mut [Vec3], parallel: bool, value: impl Fn(usize) -> Vec3 + Sync) {
        if parallel && out.len() > PARALLEL_CHUNK {
            out.par_chunks_mut(PARALLEL_CHUNK).enumerate().for_each(|(c, chunk)| {
                for (k, o) in chunk.iter_mut().enumerate() {
                    *o = value(c * PARALLEL_CHUNK + k);
                }
            });
        } else {
            for (i, o) in out.iter_mut().enumerate() {
                *o = value(i);
            }
        }
    }

    /// The springs incident to slot i as (spring, sign): +1 where i is end a. O(degree).
    pub fn incident(&self, i: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let (o0, o1, o2) = (self.off[2 * i] as usize, self.off[2 * i + 1] as usize, self.off[2 * i + 2] as usize);
        let heads = self.adj[o0..o1].iter().map(|&s| (s as usize, 1.0));
        heads.chain(self.adj[o1..o2].iter().map(|&s| (s as usize, -1.0)))
    }

    /// Kinetic energy ½ Σ m |v|² over free slots. O(slots).
    pub fn kinetic_energy(&self, v: &[Vec3]) -> f64 {
        self.mass
            .iter()
            .zip(&self.inv_mass)
            .zip(v)
            .filter(|((_, &w), _)| w > 0.0)
            .map(|((&m, _), v)| 0.5 * m * dot(*v, *v))
            .sum()
    }

    /// Elastic energy ½ Σ k (l − L)². O(springs).
    pub fn elastic_energy(&self, x: &[Vec3]) -> f64 {
        (0..self.springs())
            .map(|s| {
                let [a, b] = self.ends[s];
                let stretch = norm(sub(x[b as usize], x[a as usize])) - self.rest[s];
                0.5 * self.stiffness[s] * stretch * stretch
            })
            .sum()
    }

    /// Gravitational potential −Σ m g·x over free slots. O(slots).
    pub fn gravity_energy(&self, x: &[Vec3]) -> f64 {
        let g = self.gravity;
        self.mass
            .iter()
            .zip(&self.inv_mass)
            .zip(x)
            .filter(|((_, &w), _)| w > 0.0)
            .map(|((&m, _), x)| -m * dot(g, *x))
            .sum()
    }

    /// A bound on the largest angular frequency, ω_max² ≤ max_v Σ_{s ∋ v} 2 k_s / m_v
    /// (Gershgorin on M⁻¹K), over free slots. Explicit schemes need dt ≲ 2/ω_max. O(springs).
    pub fn omega_max(&self) -> f64 {
        let mut w2: f64 = 0.0;
        for i in 0..self.slots() {
            if self.inv_mass[i] > 0.0 {
                let k: f64 = self.incident(i).map(|(s, _)| 2.0 * self.stiffness[s]).sum();
                w2 = w2.max(k * self.inv_mass[i]);
            }
        }
        w2.sqrt()
    }
}

/// Springs per block of the vectorised spring pass.
const BLOCK: usize = 64;

/// F_s on end a of a spring (see the module docs). Zero for a zero-length spring. O(1).
#[inline(always)]
pub fn spring_force(xa: Vec3, xb: Vec3, va: Vec3, vb: Vec3, rest: f64, k: f64, c: f64) -> Vec3 {
    let d = [xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]];
    let dv = [vb[0] - va[0], vb[1] - va[1], vb[2] - va[2]];
    let s = spring_scale(d[0], d[1], d[2], dv[0], dv[1], dv[2], rest, k, c);
    [s * d[0], s * d[1], s * d[2]]
}

/// The scalar s with F_s = s·d: s = [k (l − L) l + c (dv·d)] / l², one sqrt and one division;
/// zero when l = 0.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn spring_scale(dx: f64, dy: f64, dz: f64, dvx: f64, dvy: f64, dvz: f64, rest: f64, k: f64, c: f64) -> f64 {
    let l2 = dx * dx + dy * dy + dz * dz;
    let l = l2.sqrt();
    let num = k * (l - rest) * l + c * (dvx * dx + dvy * dy + dvz * dz);
    // Division by max(l2, tiny) keeps the loop branch-free; the select zeroes l = 0.
    let q = num / l2.max(f64::MIN_POSITIVE);
    if l2 > 0.0 {
        q
    } else {
        0.0
    }
}

/// CSR of incident springs (see [`SpringSystem`]). O(slots + springs).
fn incidence(n: usize, ends: &[[u32; 2]]) -> (Vec<u32>, Vec<u32>) {
    let mut count = vec![0u32; 2 * n + 1];
    for &[a, b] in ends {
        count[2 * a as usize + 1] += 1;
        count[2 * b as usize + 2] += 1;
    }
    for i in 1..count.len() {
        count[i] += count[i - 1];
    }
    let off = count.clone();
    let mut next = count;
    let mut adj = vec![0u32; 2 * ends.len()];
    for (s, &[a, b]) in ends.iter().enumerate() {
        for slot in [2 * a as usize, 2 * b as usize + 1] {
            adj[next[slot] as usize] = s as u32;
            next[slot] += 1;
        }
    }
    (off, adj)
}
