//! The rasterizer: camera-space transform, near-plane clipping, z-buffered triangle fill.

pub(crate) use crate::mechanics::geom::{cross, dot, norm, scale, sub};
use crate::mechanics::Vec3;
use crate::mesh::{binary_exponent, times_pow2};

use super::{Image, RenderError};

/// An orthonormal camera frame with the projection constants, checked.
#[derive(Clone, Copy, Debug)]
pub(crate) struct View {
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    /// 1 / tan(fov_y / 2).
    focal: f64,
    /// Distance of the near clipping plane in front of the eye.
    near: f64,
}

impl View {
    pub(crate) fn new(camera: &super::Camera) -> Result<Self, RenderError> {
        let bad = |reason| Err(RenderError::BadCamera { camera: *camera, reason });
        let all = camera.eye.iter().chain(&camera.target).chain(&camera.up).chain([&camera.fov_y_deg]);
        if !all.into_iter().all(|c| c.is_finite()) {
            return bad("a coordinate or the field of view is not finite");
        }
        if !(camera.fov_y_deg > 0.0 && camera.fov_y_deg < 180.0) {
            return bad("the vertical field of view must be in (0, 180) degrees");
        }
        if camera.eye == camera.target {
            return bad("the eye is at the target");
        }
        let to_target = sub(camera.target, camera.eye);
        if !to_target.iter().all(|c| c.is_finite()) {
            return bad("the eye is so far from the target that their difference is past f64::MAX");
        }
        // Both vectors by a power of two (exact): a distance of 1e-170 or 1e170 has a direction.
        let (to_target, e) = fitted(to_target);
        let (camera_up, _) = fitted(camera.up);
        let length = norm(to_target);
        let forward = scale(to_target, 1.0 / length);
        let side = cross(forward, camera_up);
        let side_len = norm(side);
        if side_len <= 1e-9 * norm(camera_up) || side_len == 0.0 {
            return bad("the up vector is zero or parallel to the view direction");
        }
        let right = scale(side, 1.0 / side_len);
        let up = cross(right, forward);
        let focal = 1.0 / (camera.fov_y_deg.to_radians() / 2.0).tan();
        Ok(View { eye: camera.eye, right, up, forward, focal, near: times_pow2(1e-4 * length, e) })
    }

    /// Camera coordinates: (right, up, depth in front of the eye).
    fn camera_coords(&self, p: Vec3) -> Vec3 {
        let d = sub(p, self.eye);
        [dot(d, self.right), dot(d, self.up), dot(d, self.forward)]
    }

    pub(crate) fn eye(&self) -> Vec3 {
        self.eye
    }
}

/// `v` · 2^−e with its largest |component| in [1, 2), and e; `(v, 0)` for a zero or non-finite
/// largest component. Exact (a power of two), so a direction, a ratio or a sign read from the
/// result is the one of `v`, computed as if no product of its components could overflow or
/// underflow (and bit for bit the plain one where none does). O(1).
pub(crate) fn fitted(v: Vec3) -> (Vec3, i64) {
    let largest = v.iter().fold(0.0_f64, |m, c| m.max(c.abs()));
    if largest == 0.0 || !largest.is_finite() {
        return (v, 0);
    }
    let e = binary_exponent(largest);
    (v.map(|c| times_pow2(c, -e)), e)
}

/// |v| without overflow or underflow of the squares: ∞ only when |v| is past f64::MAX, and the
/// plain `norm(v)` bit for bit where its squares stay normal. O(1).
pub(crate) fn scaled_norm(v: Vec3) -> f64 {
    let (u, e) = fitted(v);
    times_pow2(norm(u), e)
}

/// `v / |v|` for any finite nonzero `v` (NaN components for a zero or non-finite one), bit for
/// bit `v / norm(v)` where that does not overflow or underflow. O(1).
pub(crate) fn unit(v: Vec3) -> Vec3 {
    let (u, _) = fitted(v);
    let length = norm(u);
    u.map(|c| c / length)
}

/// `to − from`, or, when that is past f64::MAX, `to/2 − from/2` (the same direction, half the
/// length): a direction for any two finite points. O(1).
pub(crate) fn direction(from: Vec3, to: Vec3) -> Vec3 {
    let d = sub(to, from);
    if d.iter().all(|c| c.is_finite()) {
        d
    } else {
        std::array::from_fn(|k| to[k] / 2.0 - from[k] / 2.0)
    }
}

/// The target of the fill: colour and depth buffers of one image.
pub(crate) struct Target<'a> {
    pub(crate) image: &'a mut Image,
    /// 1 / depth of the nearest surface drawn so far at each pixel (0 = nothing yet).
    pub(crate) inv_depth: Vec<f64>,
}

impl<'a> Target<'a> {
    pub(crate) fn new(image: &'a mut Image) -> Self {
        let n = image.width as usize * image.height as usize;
        Target { image, inv_depth: vec![0.0; n] }
    }

    /// Draws the world-space triangle `tri` in `color`: clipped against the near plane,
    /// projected, and filled where it is nearer than what is there (ties keep the earlier
    /// triangle). O(pixels of its clamped screen bounding box).
    pub(crate) fn draw(&mut self, view: &View, tri: [Vec3; 3], color: [u8; 3]) {
        let cam = tri.map(|p| view.camera_coords(p));
        let poly = clip_near(cam, view.near);
        let (w, h) = (self.image.width as f64, self.image.height as f64);
        let project = |c: Vec3| {
            let s = view.focal * h / 2.0 / c[2];
            [w / 2.0 + c[0] * s, h / 2.0 - c[1] * s, 1.0 / c[2]]
        };
        let screen: Vec<Vec3> = poly.iter().map(|&c| project(c)).collect();
        for k in 1..screen.len().saturating_sub(1) {
            self.fill([screen[0], screen[k], screen[k + 1]], color);
        }
    }

    /// Fills a screen triangle (x, y, 1/depth) by edge functions at pixel centres.
    fn fill(&mut self, v: [Vec3; 3], color: [u8; 3]) {
        let area = edge(v[0], v[1], v[2]);
        if area == 0.0 || !area.is_finite() {
            return;
        }
        let (w, h) = (self.image.width as usize, self.image.height as usize);
        let lo = |k: usize| v.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min).floor().max(0.0) as usize;
        let hi = |k: usize, n: usize| {
            let m = v.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max).ceil();
            if m < 0.0 {
                0
            } else {
                (m as usize).min(n)
            }
        };
        for y in lo(1)..hi(1, h) {
            for x in lo(0)..hi(0, w) {
                let p = [x as f64 + 0.5, y as f64 + 0.5, 0.0];
                let b = [edge(v[1], v[2], p) / area, edge(v[2], v[0], p) / area, edge(v[0], v[1], p) / area];
                if b.iter().any(|&c| c < 0.0) {
                    continue;
                }
                let inv_z = b[0] * v[0][2] + b[1] * v[1][2] + b[2] * v[2][2];
                let i = y * w + x;
                if inv_z > self.inv_depth[i] {
                    self.inv_depth[i] = inv_z;
                    self.image.rgb[3 * i..3 * i + 3].copy_from_slice(&color);
                }
            }
        }
    }
}

/// Twice the signed area of (a, b, p) in the screen plane.
fn edge(a: Vec3, b: Vec3, p: Vec3) -> f64 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

/// Sutherland–Hodgman clipping of a camera-space triangle to depth ≥ `near`: 0, 3 or 4 vertices.
fn clip_near(tri: [Vec3; 3], near: f64) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(4);
    for k in 0..3 {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        let (ina, inb) = (a[2] >= near, b[2] >= near);
        if ina {
            out.push(a);
        }
        if ina != inb {
            let t = (near - a[2]) / (b[2] - a[2]);
            out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), near]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_keeps_the_part_in_front() {
        let near = 1.0;
        assert_eq!(clip_near([[0.0, 0.0, 2.0], [1.0, 0.0, 2.0], [0.0, 1.0, 2.0]], near).len(), 3);
        assert!(clip_near([[0.0, 0.0, 0.5], [1.0, 0.0, 0.5], [0.0, 1.0, 0.5]], near).is_empty());
        let one_behind = clip_near([[0.0, 0.0, 0.0], [1.0, 0.0, 2.0], [0.0, 1.0, 2.0]], near);
        assert_eq!(one_behind.len(), 4);
        assert!(one_behind.iter().all(|p| p[2] >= near));
        let two_behind = clip_near([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 2.0]], near);
        assert_eq!(two_behind.len(), 3);
        assert!(two_behind.iter().all(|p| p[2] >= near));
    }

    /// A direction between finite points is finite and points from `from` to `to`: the plain
    /// difference where it is finite, half of it where that overflows (a survivor of the 36th
    /// mutation sample read the fallback as `to/2 + from/2`).
    #[test]
    fn direction_is_finite_and_points_from_to() {
        assert_eq!(direction([1.0, 2.0, 3.0], [4.0, 0.0, 3.0]), [3.0, -2.0, 0.0]);
        let (a, b) = ([-1.5e308, 1e308, 0.0], [1.5e308, -1e308, 2.0]);
        assert_eq!(direction(a, b), [1.5e308, -1e308, 1.0]);
        assert_eq!(direction(b, a), [-1.5e308, 1e308, -1.0]);
        let u = unit(direction(a, b));
        let expected = unit([1.5, -1.0, 0.0]);
        assert!((0..3).all(|k| (u[k] - expected[k]).abs() < 1e-15), "{u:?}");
    }
}
