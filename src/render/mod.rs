//! Software rendering of a boundary [`Surface`] to a PNG picture, with no GPU and no display.
//!
//! A fixed pinhole [`Camera`] (perspective, vertical field of view) looks at the surface; every
//! triangle is clipped against a near plane, projected and filled at pixel centres into an
//! [`Image`] with a depth buffer, so the nearest surface wins whatever the drawing order. Each
//! triangle gets one colour ([`Shading`]: flat, per-triangle RGB, or a per-triangle scalar such as
//! stress or subdivision level through a [`Colormap`]) times a Lambert factor for a headlight at
//! the eye plus an ambient term. Both sides of a triangle are lit, so the two faces of a cut show;
//! a back side is drawn slightly darker. An optional legend bar shows the colormap with its
//! minimum and maximum. [`Image::encode_png`] writes the result with the encoder of [`png`]
//! (written here: CRC-32, Adler-32, DEFLATE with fixed Huffman codes and LZ77).
//!
//! Everything is single-threaded f64 arithmetic in a fixed order, so the same input gives the
//! same bytes. Cost of [`render`]: O(width · height + Σ over triangles of their clamped screen
//! bounding box).
//!
//! ```
//! use topomech::{generate, render, surface};
//!
//! let (points, tets) = generate::kuhn_cube(2);
//! let s = surface::boundary_surface_of_tets(&points, &tets).unwrap();
//! let (lo, hi) = s.bounds().unwrap();
//! let camera = render::Camera::fit(lo, hi, [-1.0, -2.0, -1.5]);
//! let image = render::render(&s, &render::Shading::Flat([200, 120, 100]), &camera, 64, 48).unwrap();
//! assert_ne!(image.pixel(32, 24), Some(render::Style::default().background)); // the cube is in the middle
//! assert!(image.encode_png().unwrap().starts_with(b"\x89PNG"));
//! ```

mod colormap;
mod legend;
pub mod png;
mod raster;

use std::path::{Path, PathBuf};

pub use colormap::Colormap;

use crate::mechanics::Vec3;
use crate::surface::Surface;
use raster::{cross, direction, dot, fitted, norm, scaled_norm, sub, unit, Target, View};

/// The largest image [`render`] and [`Image::new`] accept, in pixels (a bound on the buffers
/// they allocate: 3 bytes per pixel for the picture, 8 more for the depth buffer of [`render`]).
pub const MAX_PIXELS: u64 = 1 << 26;

/// Errors of the renderer and of the PNG writer.
///
/// # Examples
///
/// ```
/// use topomech::render::{render, Camera, RenderError, Shading};
/// use topomech::{generate::kuhn_cube, surface::boundary_surface_of_tets};
///
/// let (points, tets) = kuhn_cube(1);
/// let s = boundary_surface_of_tets(&points, &tets).unwrap();
/// let camera = Camera::fit([0.0; 3], [1.0; 3], [0.0, 1.0, 0.0]);
/// let flat = Shading::Flat([0; 3]);
/// assert!(matches!(render(&s, &flat, &camera, 0, 8), Err(RenderError::BadSize { width: 0, height: 8 })));
/// let blind = Camera { target: camera.eye, ..camera };
/// assert!(matches!(render(&s, &flat, &blind, 8, 8), Err(RenderError::BadCamera { .. })));
/// ```
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A zero or too large image size.
    #[error("image size {width}x{height} is not allowed (both must be positive, at most {MAX_PIXELS} pixels)")]
    BadSize {
        /// Asked width.
        width: u32,
        /// Asked height.
        height: u32,
    },
    /// The camera does not define a view.
    #[error("bad camera {camera:?}: {reason}")]
    BadCamera {
        /// The camera.
        camera: Camera,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// A surface vertex has a NaN or infinite coordinate.
    #[error("surface vertex {vertex} (vertex id {id}) has a non-finite position {position:?}")]
    NonFinitePosition {
        /// Index of the vertex in the surface.
        vertex: usize,
        /// Its vertex cell id (`Surface::vertex_ids`), or `u32::MAX` if the surface has none.
        id: u32,
        /// The position.
        position: Vec3,
    },
    /// A triangle refers to a vertex that the surface does not have.
    #[error("triangle {triangle} refers to vertex {index}, but the surface has {vertices} vertices")]
    BadTriangle {
        /// The triangle's index.
        triangle: usize,
        /// The bad vertex index.
        index: u32,
        /// The number of vertices.
        vertices: usize,
    },
    /// A per-triangle array does not have one entry per triangle.
    #[error("{got} per-triangle values for {expected} triangles")]
    ValueCount {
        /// Its length.
        got: usize,
        /// The number of triangles.
        expected: usize,
    },
    /// A per-triangle value is NaN or infinite.
    #[error("the value of triangle {triangle} is {value}, not a finite number")]
    NonFiniteValue {
        /// The triangle's index.
        triangle: usize,
        /// The value.
        value: f64,
    },
    /// A [`Style::ambient`] that is NaN or outside [0, 1].
    #[error("style ambient {ambient} is not a share of the light in [0, 1]")]
    BadAmbient {
        /// The value asked for.
        ambient: f64,
    },
    /// A colour scale whose ends are not finite or are reversed.
    #[error("colour scale range ({lo}, {hi}) must be finite with lo <= hi")]
    BadRange {
        /// Its lower end.
        lo: f64,
        /// Its upper end.
        hi: f64,
    },
    /// An image whose pixel buffer does not match its size (the fields are public).
    #[error("image {width}x{height} has {len} bytes of RGB, expected 3 per pixel")]
    BadBuffer {
        /// Width.
        width: u32,
        /// Height.
        height: u32,
        /// Length of `rgb`.
        len: usize,
    },
    /// The PNG file could not be written (the cause names the file).
    #[error("cannot write the PNG file {source}")]
    Write {
        /// The file asked for.
        path: PathBuf,
        /// The cause.
        source: crate::store::StoreError,
    },
}

/// A pinhole camera: at `eye`, looking at `target`, with `up` pointing up on the picture, and a
/// vertical field of view of `fov_y_deg` degrees (pixels are square, so the horizontal field of
/// view follows from the aspect ratio).
///
/// Invariant checked by [`render`] (a [`RenderError::BadCamera`] otherwise): finite coordinates,
/// `eye != target` with `target − eye` finite, `up` not parallel to the view direction,
/// `0 < fov_y_deg < 180`. Lengths do not matter: an eye 1e-170 or 1e150 from its target, or an
/// `up` of length 1e-200, is as good as one of length 1.
///
/// # Examples
///
/// ```
/// use topomech::render::Camera;
///
/// let c = Camera { eye: [0.0, -4.0, 0.0], target: [0.0; 3], up: [0.0, 0.0, 1.0], fov_y_deg: 45.0 };
/// assert_eq!(c, Camera::looking_at([0.0, -4.0, 0.0], [0.0; 3], [0.0, 0.0, 1.0], 45.0));
/// let fitted = Camera::fit([-1.0; 3], [1.0; 3], [0.0, 0.0, -1.0]); // looking down
/// assert_eq!(fitted.target, [0.0; 3]);
/// assert!(fitted.eye[2] > 1.0 && fitted.fov_y_deg > 0.0 && fitted.fov_y_deg < 180.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Centre of projection.
    pub eye: Vec3,
    /// The point seen at the centre of the picture.
    pub target: Vec3,
    /// A vector whose projection points up on the picture (need not be orthogonal to the view).
    pub up: Vec3,
    /// Vertical field of view, in degrees.
    pub fov_y_deg: f64,
}

impl Camera {
    /// The field of view [`Camera::fit`] uses, in degrees.
    pub const FIT_FOV_Y_DEG: f64 = 30.0;

    /// A camera at `eye` looking at `target`. O(1); checked when used.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::render::Camera;
    ///
    /// let c = Camera::looking_at([0.0, -5.0, 0.0], [0.0; 3], [0.0, 0.0, 1.0], 40.0);
    /// assert_eq!((c.eye[1], c.target, c.fov_y_deg), (-5.0, [0.0; 3], 40.0));
    /// ```
    pub fn looking_at(eye: Vec3, target: Vec3, up: Vec3, fov_y_deg: f64) -> Camera {
        Camera { eye, target, up, fov_y_deg }
    }

    /// A camera looking along `view_dir` at the centre of the box `min..max`, far enough that the
    /// box's bounding sphere fits in the vertical field of view ([`Camera::FIT_FOV_Y_DEG`]) with a
    /// 5 % margin — and in the horizontal one whenever the picture is at least as wide as high.
    /// `up` is +z, or +y when `view_dir` is within about 8° of the z axis. Compute it once (e.g.
    /// from the rest shape) to keep the camera fixed over an animation. O(1).
    ///
    /// Any finite box of positive size is framed, from 1e-300 to 1e300 wide: the centre is
    /// `min/2 + max/2` where `min + max` would overflow, and the radius is measured without
    /// overflow or underflow of its squares. A zero or non-finite `view_dir` or box gives a camera
    /// that [`render`] refuses; a box of zero size is framed as if its radius were 1. The eye
    /// stands about 4 radii from the centre, so for a box whose half-diagonal is past about
    /// f64::MAX / 5 (or a centre that close to ±f64::MAX) its coordinates overflow to ±∞ and
    /// [`render`] refuses the camera as not finite.
    ///
    /// ```
    /// use topomech::render::Camera;
    ///
    /// let c = Camera::fit([0.0; 3], [2.0; 3], [0.0, 1.0, 0.0]);
    /// assert_eq!(c.target, [1.0; 3]);
    /// assert!(c.eye[1] < 0.0 && c.eye[0] == 1.0 && c.eye[2] == 1.0);
    /// ```
    pub fn fit(min: Vec3, max: Vec3, view_dir: Vec3) -> Camera {
        let target = crate::mesh::midpoint(min, max);
        let radius = match half_diagonal(min, max) {
            r if r > 0.0 => r,
            _ => 1.0,
        };
        let half_fov = (Self::FIT_FOV_Y_DEG / 2.0).to_radians();
        let distance = 1.05 * radius / half_fov.sin();
        let dir = unit(view_dir);
        let eye = std::array::from_fn(|k| target[k] - distance * dir[k]);
        let up = if dir[2].abs() < 0.99 { [0.0, 0.0, 1.0] } else { [0.0, 1.0, 0.0] };
        Camera { eye, target, up, fov_y_deg: Self::FIT_FOV_Y_DEG }
    }
}

/// Half the length of the diagonal of the box `min..max`, for any finite box (∞ or NaN for a
/// non-finite one); bit for bit `|max − min| / 2` where its squares neither overflow nor
/// underflow. O(1).
fn half_diagonal(min: Vec3, max: Vec3) -> f64 {
    let d = sub(max, min);
    if d.iter().all(|c| c.is_finite()) {
        scaled_norm(d) / 2.0
    } else {
        scaled_norm(std::array::from_fn(|k| max[k] / 2.0 - min[k] / 2.0))
    }
}

/// An 8-bit RGB picture, rows top to bottom.
///
/// Invariant (checked by [`Image::encode_png`]): `rgb.len() == 3 · width · height`.
/// [`Image::new`] makes images of 1 to [`MAX_PIXELS`] pixels; the fields are public, so a
/// larger one can be built by hand from its buffer.
///
/// # Examples
///
/// ```
/// use topomech::render::Image;
///
/// let mut img = Image::new(3, 2, [0; 3]).unwrap();
/// img.set_pixel(2, 1, [7, 8, 9]);
/// assert_eq!(img.rgb.len(), 3 * img.width as usize * img.height as usize);
/// assert_eq!(&img.rgb[3 * (1 * 3 + 2)..][..3], &[7, 8, 9]); // row-major, rows top to bottom
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixel (x, y) is `rgb[3·(y·width + x)..][..3]`.
    pub rgb: Vec<u8>,
}

impl Image {
    /// A `width` × `height` image filled with `background`. The size is checked first, in
    /// O(1), as [`render`] checks it: both sides positive and at most [`MAX_PIXELS`] pixels in
    /// all, so nothing is allocated for a size refused. O(pixels).
    ///
    /// # Errors
    /// [`RenderError::BadSize`] naming the size, for a zero side or more than [`MAX_PIXELS`]
    /// pixels.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::render::{Image, RenderError};
    ///
    /// let img = Image::new(4, 2, [1, 2, 3]).unwrap();
    /// assert_eq!(img.rgb.len(), 3 * 4 * 2);
    /// assert_eq!(img.pixel(3, 1), Some([1, 2, 3]));
    /// assert!(matches!(Image::new(0, 2, [0; 3]), Err(RenderError::BadSize { width: 0, height: 2 })));
    /// let too_big = Image::new(u32::MAX, u32::MAX, [0; 3]); // refused, not allocated
    /// assert!(matches!(too_big, Err(RenderError::BadSize { width: u32::MAX, height: u32::MAX })));
    /// assert!(Image::new(1 << 13, (1 << 13) + 1, [0; 3]).is_err()); // one row past MAX_PIXELS
    /// ```
    pub fn new(width: u32, height: u32, background: [u8; 3]) -> Result<Image, RenderError> {
        check_size(width, height)?;
        let n = width as usize * height as usize;
        Ok(Image { width, height, rgb: background.repeat(n) })
    }

    /// The colour of pixel (x, y), `None` outside the image. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::render::Image;
    ///
    /// let img = Image::new(4, 2, [9, 9, 9]).unwrap();
    /// assert_eq!(img.pixel(0, 0), Some([9, 9, 9]));
    /// assert_eq!((img.pixel(4, 0), img.pixel(0, 2)), (None, None)); // outside
    /// ```
    pub fn pixel(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        let i = self.index(x, y)?;
        self.rgb.get(i..i + 3).map(|p| [p[0], p[1], p[2]])
    }

    /// Sets pixel (x, y); does nothing outside the image. O(1).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::render::Image;
    ///
    /// let mut img = Image::new(3, 3, [0; 3]).unwrap();
    /// img.set_pixel(1, 2, [255, 0, 0]);
    /// img.set_pixel(7, 7, [255, 0, 0]); // outside: ignored
    /// assert_eq!(img.pixel(1, 2), Some([255, 0, 0]));
    /// assert_eq!(img.rgb.iter().filter(|&&b| b == 255).count(), 1);
    /// ```
    pub fn set_pixel(&mut self, x: u32, y: u32, color: [u8; 3]) {
        if let Some(p) = self.index(x, y).and_then(|i| self.rgb.get_mut(i..i + 3)) {
            p.copy_from_slice(&color);
        }
    }

    fn index(&self, x: u32, y: u32) -> Option<usize> {
        (x < self.width && y < self.height).then(|| 3 * (y as usize * self.width as usize + x as usize))
    }

    /// The image as a PNG file (8-bit RGB, no interlace, adaptive row filters, IDAT chunks of at
    /// most 1 MiB).
    /// O(pixels).
    ///
    /// # Errors
    /// [`RenderError::BadSize`] for a zero dimension; [`RenderError::BadBuffer`] when `rgb` does
    /// not hold 3 bytes per pixel.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::render::Image;
    ///
    /// let png = Image::new(5, 3, [0, 128, 255]).unwrap().encode_png().unwrap();
    /// assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    /// assert_eq!(&png[12..16], b"IHDR");
    /// assert_eq!((&png[16..20], &png[20..24]), (&5u32.to_be_bytes()[..], &3u32.to_be_bytes()[..])); // width, height
    /// assert!(Image { width: 0, height: 3, rgb: vec![] }.encode_png().is_err());
    /// let broken = Image { width: 2, height: 2, rgb: vec![0; 5] };
    /// assert!(broken.encode_png().is_err());
    /// ```
    pub fn encode_png(&self) -> Result<Vec<u8>, RenderError> {
        if self.width == 0 || self.height == 0 || self.width > i32::MAX as u32 || self.height > i32::MAX as u32 {
            return Err(RenderError::BadSize { width: self.width, height: self.height });
        }
        if self.rgb.len() as u64 != 3 * self.width as u64 * self.height as u64 {
            return Err(RenderError::BadBuffer { width: self.width, height: self.height, len: self.rgb.len() });
        }
        Ok(png::encode_rgb(self.width, self.height, &self.rgb))
    }

    /// Writes [`Image::encode_png`] to `path` atomically (temporary file, then rename; see
    /// [`crate::store::write_atomically`]). O(pixels).
    ///
    /// # Errors
    /// As [`Image::encode_png`]; [`RenderError::Write`] naming `path`.
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::render::Image;
    ///
    /// let img = Image::new(2, 2, [10, 20, 30]).unwrap();
    /// let path = std::env::temp_dir().join(format!("topomech_doc_{}.png", std::process::id()));
    /// img.write_png(&path).unwrap();
    /// assert_eq!(std::fs::read(&path).unwrap(), img.encode_png().unwrap());
    /// std::fs::remove_file(&path).unwrap();
    /// assert!(img.write_png(std::path::Path::new("/nonexistent-dir/x.png")).is_err());
    /// ```
    pub fn write_png(&self, path: &Path) -> Result<(), RenderError> {
        let bytes = self.encode_png()?;
        crate::store::write_atomically(path, &bytes)
            .map_err(|source| RenderError::Write { path: path.to_path_buf(), source })
    }
}

/// How the triangles are coloured (before lighting).
///
/// # Examples
///
/// ```
/// use topomech::render::{render, Camera, Colormap, Shading};
/// use topomech::{generate::kuhn_cube, surface::boundary_surface_of_tets};
///
/// let (points, tets) = kuhn_cube(1);
/// let s = boundary_surface_of_tets(&points, &tets).unwrap();
/// let camera = Camera::fit([0.0; 3], [1.0; 3], [0.0, 1.0, 0.0]);
/// let per_face = Shading::Colors(vec![[0, 0, 200]; s.triangles.len()]);
/// let [r, _, b] = render(&s, &per_face, &camera, 16, 16).unwrap().pixel(8, 8).unwrap();
/// assert!(r == 0 && b > 0);
/// let scalar = Shading::PerTriangle { values: vec![0.0; 12], range: (1.0, 0.0), colormap: Colormap::Sequential };
/// assert!(render(&s, &scalar, &camera, 16, 16).is_err()); // reversed range
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum Shading {
    /// One colour for the whole surface.
    Flat([u8; 3]),
    /// One colour per triangle (e.g. a palette indexed by subdivision level).
    Colors(Vec<[u8; 3]>),
    /// One scalar per triangle (stress, level, …) through `colormap`, with `range.0` at its start
    /// and `range.1` at its end (values outside are clamped). Keep `range` fixed over an animation
    /// so colours compare across frames.
    PerTriangle {
        /// One value per triangle.
        values: Vec<f64>,
        /// The ends of the scale.
        range: (f64, f64),
        /// The colours.
        colormap: Colormap,
    },
}

impl Shading {
    /// [`Shading::PerTriangle`] with `range` = (min, max) of the finite `values` ((0, 1) if there
    /// are none). O(values).
    ///
    /// # Examples
    ///
    /// ```
    /// use topomech::render::{Colormap, Shading};
    ///
    /// let Shading::PerTriangle { range, .. } = Shading::by_values(vec![2.0, f64::NAN, -1.0], Colormap::Sequential)
    /// else { panic!() };
    /// assert_eq!(range, (-1.0, 2.0)); // NaN skipped
    /// let Shading::PerTriangle { range, .. } = Shading::by_values(vec![], Colormap::Diverging) else { panic!() };
    /// assert_eq!(range, (0.0, 1.0));
    /// ```
    pub fn by_values(values: Vec<f64>, colormap: Colormap) -> Shading {
        let finite = values.iter().copied().filter(|v| v.is_finite());
        let range = finite.fold(None, |r: Option<(f64, f64)>, v| Some(r.map_or((v, v), |(a, b)| (a.min(v), b.max(v)))));
        Shading::PerTriangle { values, range: range.unwrap_or((0.0, 1.0)), colormap }
    }

    /// The base colour of each triangle, checked against the surface. O(triangles).
    fn colors(&self, triangles: usize) -> Result<Vec<[u8; 3]>, RenderError> {
        let count = |got: usize| {
            if got == triangles {
                Ok(())
            } else {
                Err(RenderError::ValueCount { got, expected: triangles })
            }
        };
        match self {
            Shading::Flat(c) => Ok(vec![*c; triangles]),
            Shading::Colors(colors) => count(colors.len()).map(|()| colors.clone()),
            Shading::PerTriangle { values, range: (lo, hi), colormap } => {
                count(values.len())?;
                if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                    return Err(RenderError::BadRange { lo: *lo, hi: *hi });
                }
                if let Some((triangle, &value)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                    return Err(RenderError::NonFiniteValue { triangle, value });
                }
                Ok(values.iter().map(|&v| colormap.color_in(v, *lo, *hi)).collect())
            }
        }
    }

    /// The colour scale to show in a legend, if the shading has one.
    fn scale(&self) -> Option<(Colormap, f64, f64)> {
        match self {
            Shading::PerTriangle { range, colormap, .. } => Some((*colormap, range.0, range.1)),
            _ => None,
        }
    }
}

/// Picture settings besides the camera and the colours.
///
/// # Examples
///
/// ```
/// use topomech::render::Style;
///
/// let style = Style::default();
/// assert_eq!(style.background, [255, 255, 255]);
/// assert!(style.legend && (0.0..=1.0).contains(&style.ambient));
/// let dark = Style { background: [0, 0, 0], ..style };
/// assert_ne!(dark, style);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Colour where no triangle is seen.
    pub background: [u8; 3],
    /// Share of the light that does not depend on the angle, in [0, 1] ([`render_styled`]
    /// refuses any other value, NaN included, with [`RenderError::BadAmbient`]).
    pub ambient: f64,
    /// Draw a colour bar with its minimum and maximum on the right (per-scalar shading only).
    pub legend: bool,
}

impl Default for Style {
    /// White background, ambient 0.3, legend on.
    fn default() -> Self {
        Style { background: [255, 255, 255], ambient: 0.3, legend: true }
    }
}

/// Renders `surface` as seen by `camera` into a `width` × `height` picture with the default
/// [`Style`]. See [`render_styled`].
///
/// # Errors
/// As [`render_styled`].
///
/// # Examples
///
/// ```
/// use topomech::render::{render, Camera, Shading};
/// use topomech::{generate::kuhn_cube, surface::boundary_surface_of_tets};
///
/// let (points, tets) = kuhn_cube(1);
/// let s = boundary_surface_of_tets(&points, &tets).unwrap();
/// let camera = Camera::fit([0.0; 3], [1.0; 3], [0.0, 1.0, 0.0]);
/// let img = render(&s, &Shading::Flat([200, 0, 0]), &camera, 32, 32).unwrap();
/// assert_eq!(img.pixel(0, 0), Some([255, 255, 255])); // background in the corner
/// let [r, g, b] = img.pixel(16, 16).unwrap(); // the cube's face in the middle, lit
/// assert!(r > 0 && g == 0 && b == 0);
/// assert!(render(&s, &Shading::Colors(vec![]), &camera, 32, 32).is_err()); // 0 colours for 12 triangles
/// ```
pub fn render(
    surface: &Surface,
    shading: &Shading,
    camera: &Camera,
    width: u32,
    height: u32,
) -> Result<Image, RenderError> {
    render_styled(surface, shading, camera, width, height, &Style::default())
}

/// Renders `surface` as seen by `camera`: z-buffered, each triangle in its [`Shading`] colour
/// scaled by `ambient + (1 − ambient)·|cos θ|`, θ the angle between its normal and the direction
/// to the eye (a headlight), times 0.8 on its back side; a triangle behind the eye is clipped at
/// a near plane 10⁻⁴·|target − eye| in front of it. With `style.legend` and per-scalar shading, a
/// colour bar with the range's ends is drawn on the right.
///
/// Cost: O(width · height + triangles + Σ clamped screen bounding boxes).
///
/// # Errors
/// [`RenderError::BadSize`], [`RenderError::BadCamera`], [`RenderError::BadAmbient`],
/// [`RenderError::BadTriangle`], [`RenderError::NonFinitePosition`], and for the shading
/// [`RenderError::ValueCount`], [`RenderError::BadRange`], [`RenderError::NonFiniteValue`], in
/// that order. Nothing is drawn on error; the size, the camera and the ambient share are checked
/// before anything is allocated.
///
/// # Examples
///
/// ```
/// use topomech::render::{render_styled, Camera, Shading, Style};
/// use topomech::{generate::kuhn_cube, surface::boundary_surface_of_tets};
///
/// let (points, tets) = kuhn_cube(1);
/// let s = boundary_surface_of_tets(&points, &tets).unwrap();
/// let camera = Camera::fit([0.0; 3], [1.0; 3], [0.0, 1.0, 0.0]);
/// let style = Style { background: [0, 0, 0], ambient: 1.0, legend: false };
/// let img = render_styled(&s, &Shading::Flat([10, 200, 30]), &camera, 32, 32, &style).unwrap();
/// assert_eq!(img.pixel(16, 16), Some([10, 200, 30])); // ambient 1: the base colour exactly
/// assert_eq!(img.pixel(0, 0), Some([0, 0, 0]));
/// ```
pub fn render_styled(
    surface: &Surface,
    shading: &Shading,
    camera: &Camera,
    width: u32,
    height: u32,
    style: &Style,
) -> Result<Image, RenderError> {
    check_size(width, height)?;
    let view = View::new(camera)?;
    let ambient = style.ambient;
    if !(0.0..=1.0).contains(&ambient) {
        return Err(RenderError::BadAmbient { ambient });
    }
    check_surface(surface)?;
    let colors = shading.colors(surface.triangles.len())?;
    let mut image = Image::new(width, height, style.background)?;
    let mut target = Target::new(&mut image);
    for (tri, &base) in surface.triangles.iter().zip(&colors) {
        let p = tri.map(|i| surface.positions[i as usize]);
        let light = ambient + (1.0 - ambient) * headlight(p, view.eye());
        target.draw(&view, p, base.map(|c| (c as f64 * light).round().clamp(0.0, 255.0) as u8));
    }
    if let (true, Some((map, lo, hi))) = (style.legend, shading.scale()) {
        legend::draw(&mut image, map, lo, hi);
    }
    Ok(image)
}

/// |cos θ| between the triangle's normal and the direction to the eye, times 0.8 when the eye
/// sees its back; 0 for a degenerate triangle. Scale-free: each edge, the normal and the
/// direction to the eye are brought to components near 1 by a power of two first, so a
/// triangle of edge 1e-150 or 1e150 is lit as one of edge 1 (bit for bit, where the plain
/// products neither overflow nor underflow). O(1).
fn headlight(p: [Vec3; 3], eye: Vec3) -> f64 {
    let (u, _) = fitted(direction(p[0], p[1]));
    let (v, _) = fitted(direction(p[0], p[2]));
    let (n, _) = fitted(cross(u, v));
    let (to_eye, _) = fitted(direction(centroid(p), eye));
    let denom = norm(n) * norm(to_eye);
    if denom == 0.0 || !denom.is_finite() {
        return 0.0;
    }
    let cos = dot(n, to_eye) / denom;
    if cos >= 0.0 {
        cos
    } else {
        -0.8 * cos
    }
}

/// The centroid of a triangle, `(a + b + c) / 3`, or `a/3 + b/3 + c/3` where the sum would
/// overflow. O(1).
fn centroid(p: [Vec3; 3]) -> Vec3 {
    std::array::from_fn(|k| {
        let sum = p[0][k] + p[1][k] + p[2][k];
        if sum.is_finite() {
            sum / 3.0
        } else {
            p[0][k] / 3.0 + p[1][k] / 3.0 + p[2][k] / 3.0
        }
    })
}

/// [`RenderError::BadSize`] unless both sides are positive and the image has at most
/// [`MAX_PIXELS`] pixels. O(1).
fn check_size(width: u32, height: u32) -> Result<(), RenderError> {
    if width == 0 || height == 0 || width as u64 * height as u64 > MAX_PIXELS {
        return Err(RenderError::BadSize { width, height });
    }
    Ok(())
}

fn check_surface(surface: &Surface) -> Result<(), RenderError> {
    let vertices = surface.positions.len();
    for (triangle, tri) in surface.triangles.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertices) {
            return Err(RenderError::BadTriangle { triangle, index, vertices });
        }
    }
    if let Some((vertex, &position)) =
        surface.positions.iter().enumerate().find(|(_, p)| p.iter().any(|c| !c.is_finite()))
    {
        let id = surface.vertex_ids.get(vertex).copied().unwrap_or(u32::MAX);
        return Err(RenderError::NonFinitePosition { vertex, id, position });
    }
    Ok(())
}
