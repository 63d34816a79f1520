//! What the demo writes into its output directory:
//!
//! ```text
//!   scene.pvd, scene_NNNNNN.vtu   the body every tenth of a stage (ParaView: File > Open scene.pvd),
//!                                 point vectors displacement, velocity, stress (principal tensile
//!                                 stress: magnitude × direction)
//!   surface.obj                   the final body's boundary surface (one triangle per boundary face)
//!   refined.obj                   the refined map's boundary (flat vertices fanned)
//!   N_stage.png                   the boundary surface from one fixed camera after each stage
//! ```

use std::path::{Path, PathBuf};

use topomech::cut;
use topomech::mechanics::Vec3;
use topomech::render::{self, Camera, Colormap, Shading};
use topomech::surface::{self, Surface};
use topomech::vtk::{body_tets, Frame, Series};

use super::scene::{Scene, SceneConfig};
use super::DemoError;

/// The output directory and what was written into it.
pub struct Output {
    dir: PathBuf,
    series: Series,
    /// The `.vtu` files of the series, in order.
    pub frames: Vec<PathBuf>,
    /// The OBJ files.
    pub objs: Vec<PathBuf>,
    /// The PNG files.
    pub pictures: Vec<PathBuf>,
    camera: Camera,
    stress_range: (f64, f64),
}

/// Picture size in pixels.
pub const WIDTH: u32 = 800;
/// See [`WIDTH`].
pub const HEIGHT: u32 = 600;

/// The fixed camera: it frames the rest shape's box, extended below by a third of the longest
/// extent so the sagging body stays in view, looking across the longest axis (along −y for the
/// liver, so its pinned end is on the right) from slightly above. O(1).
pub fn camera(c: &SceneConfig) -> Camera {
    let (mut lo, hi) = (c.lo, c.hi);
    lo[c.up_axis] -= c.extent() / 3.0;
    let side = 3 - c.long_axis - c.up_axis;
    let mut view = [0.0; 3];
    view[side] = -1.0;
    view[c.up_axis] = -0.3;
    Camera::fit(lo, hi, view)
}

impl Output {
    /// Creates `dir` (and parents); the camera is fixed from `config`'s rest box. O(1).
    ///
    /// # Errors
    /// [`DemoError::Vtk`] naming the directory.
    pub fn new(dir: &Path, config: &SceneConfig) -> Result<Self, DemoError> {
        let series = Series::new(dir, "scene")?;
        Ok(Output {
            dir: dir.to_path_buf(),
            series,
            frames: Vec::new(),
            objs: Vec::new(),
            pictures: Vec::new(),
            camera: camera(config),
            stress_range: (0.0, 1.0),
        })
    }

    /// Fixes the stress colour scale of the following pictures to (0, `max`) (ignored unless
    /// positive and finite). O(1).
    pub fn set_stress_scale(&mut self, max: f64) {
        if max.is_finite() && max > 0.0 {
            self.stress_range = (0.0, max);
        }
    }

    /// Renders the scene's boundary surface coloured by the mean principal stress of each
    /// triangle's vertices (on the fixed scale) and writes it as `name`. O(pixels + surface).
    ///
    /// # Errors
    /// [`DemoError::Render`] naming the file; [`DemoError::Sim`] if the simulation does not
    /// follow the body (a bug of the demo).
    pub fn stress_picture(&mut self, name: &str, scene: &Scene) -> Result<(), DemoError> {
        let surface = surface::boundary_surface(&scene.body);
        let stress = cut::principal_stress(&scene.body, &scene.sim)
            .map_err(|source| DemoError::Sim { stage: "picture", source })?;
        let at = |i: u32| stress.get(surface.vertex_ids[i as usize] as usize).map_or(0.0, |s| s.magnitude);
        let values = surface.triangles.iter().map(|t| t.iter().map(|&i| at(i)).sum::<f64>() / 3.0).collect();
        let shading = Shading::PerTriangle { values, range: self.stress_range, colormap: Colormap::Sequential };
        self.picture(name, &surface, &shading)
    }

    /// Renders `surface` with `shading` from the fixed camera and writes it as `name`.
    /// O(pixels + surface).
    ///
    /// # Errors
    /// [`DemoError::Render`] naming the file.
    pub fn picture(&mut self, name: &str, surface: &Surface, shading: &Shading) -> Result<(), DemoError> {
        let path = self.path(name);
        let image = render::render(surface, shading, &self.camera, WIDTH, HEIGHT)?;
        image.write_png(&path)?;
        self.pictures.push(path);
        Ok(())
    }

    /// The `.pvd` file. O(1).
    pub fn pvd(&self) -> PathBuf {
        self.series.pvd_path()
    }

    /// A path in the output directory. O(1).
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Writes the scene's body as the next frame at its simulated time. O(darts + points).
    ///
    /// # Errors
    /// [`DemoError::Vtk`].
    pub fn frame(&mut self, scene: &Scene) -> Result<(), DemoError> {
        let body = &scene.body;
        let m = body.attrs();
        let points = m.position().as_slice();
        let displacement: Vec<Vec3> = points
            .iter()
            .zip(m.rest_position().as_slice())
            .map(|(p, r)| [p[0] - r[0], p[1] - r[1], p[2] - r[2]])
            .collect();
        let stress = vertex_stress(scene, points.len())?;
        let tets = body_tets(body);
        let frame = Frame {
            points,
            tets: &tets,
            vectors: vec![
                ("displacement", &displacement),
                ("velocity", m.velocity().as_slice()),
                ("stress", &stress[..]),
            ],
        };
        let path = self.series.push(scene.time, &frame)?;
        self.frames.push(path);
        Ok(())
    }

    /// Writes `surface` as `name` (Wavefront OBJ). O(surface).
    ///
    /// # Errors
    /// [`DemoError::Surface`] naming the file.
    pub fn obj(&mut self, name: &str, surface: &Surface) -> Result<(), DemoError> {
        let path = self.path(name);
        surface.write_obj(&path)?;
        self.objs.push(path);
        Ok(())
    }
}

/// The principal tensile stress of every vertex slot as magnitude × direction, padded with zeros
/// to `len` entries. O(springs + slots).
///
/// # Errors
/// [`DemoError::Sim`] if the simulation does not follow the body (a bug of the demo).
pub fn vertex_stress(scene: &Scene, len: usize) -> Result<Vec<Vec3>, DemoError> {
    let stress =
        cut::principal_stress(&scene.body, &scene.sim).map_err(|source| DemoError::Sim { stage: "frame", source })?;
    let mut out: Vec<Vec3> = stress.iter().map(|s| s.direction.map(|c| c * s.magnitude)).collect();
    out.resize(len, [0.0; 3]);
    out.truncate(len);
    Ok(out)
}
