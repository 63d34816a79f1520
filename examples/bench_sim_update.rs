//! The cost of following one face dissociation in a running simulation: `dissociate_face` then
//! `Simulation::update` with its touched cells, timed per operation (calling thread's CPU time)
//! over many inner faces, each dissociated once; prints the median and 90th percentile of the
//! dissociation alone and of the update alone. The update is meant to cost O(touched cells),
//! not O(mesh), so its time should not grow with the mesh.
//!
//!     cargo run --release --example bench_sim_update                 # built-in liver_547
//!     cargo run --release --example bench_sim_update -- MESH [FACES]
//!     cargo run --release --example bench_sim_update -- cube:N [FACES]    # Kuhn cube, 6 N³ tets

use std::path::Path;

#[path = "common/cpu_time.rs"]
mod cpu_time;
use cpu_time::thread_cpu_seconds;
use topomech::cut::dissociate_face;
use topomech::generate::kuhn_cube;
use topomech::load;
use topomech::mechanics::{Body, Integrator, Material, Simulation, StepConfig};

fn now() -> f64 {
    thread_cpu_seconds().unwrap_or_else(|| {
        std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64())
    })
}

fn percentile(times: &mut [f64], q: f64) -> f64 {
    times.sort_by(f64::total_cmp);
    times[((times.len() - 1) as f64 * q) as usize]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (points, tets) = match args.first() {
        Some(cube) if cube.starts_with("cube:") => kuhn_cube(cube[5..].parse().expect("cube:N with N a number")),
        Some(path) => {
            load::load_tet_map(Path::new(path)).map(|l| (l.mesh.points, l.mesh.tets)).expect("the mesh loads")
        }
        None => load::load_builtin().map(|l| (l.mesh.points, l.mesh.tets)).expect("the mesh loads"),
    };
    let faces: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(500);
    let (mut body, _) = Body::from_tets(&points, &tets, Material::default()).expect("the body builds");
    let config = StepConfig::new(Integrator::Symplectic, 1e-5);
    let mut sim = Simulation::new(&mut body, [0.0, 0.0, -9.81], config).expect("the simulation builds");
    // Inner faces spread over the mesh: every k-th α3-sewn dart, one per face.
    let map = body.map();
    let mut darts: Vec<_> = map.darts().filter(|&d| !map.is_free(3, d)).collect();
    let step = (darts.len() / faces.max(1)).max(1);
    darts = darts.into_iter().step_by(step).collect();
    let (mut cut_us, mut update_us) = (Vec::new(), Vec::new());
    for d in darts {
        if body.map().is_free(3, d) {
            continue; // dissociated already, as a side of an earlier face
        }
        let t0 = now();
        let dis = dissociate_face(&mut body, d).expect("an inner face dissociates");
        let t1 = now();
        sim.update(&mut body, &dis.touched).expect("the simulation follows");
        let t2 = now();
        cut_us.push((t1 - t0) * 1e6);
        update_us.push((t2 - t1) * 1e6);
        if cut_us.len() == faces {
            break;
        }
    }
    sim.step(&mut body).expect("the cut body steps");
    println!(
        "[sim_update] vertices {} tets {} faces {}: dissociate p50 {:.2} p90 {:.2} us; Simulation::update p50 {:.2} p90 {:.2} us",
        points.len(),
        tets.len(),
        cut_us.len(),
        percentile(&mut cut_us, 0.5),
        percentile(&mut cut_us, 0.9),
        percentile(&mut update_us, 0.5),
        percentile(&mut update_us, 0.9),
    );
}
