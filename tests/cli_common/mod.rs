//! What the suites that run the `topomech` binary share: a fresh scratch directory per test, a
//! run inside it, lossy text of an output, and a small MSH 2.2 writer for meshes made in a test.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output};
use std::time::{Duration, Instant};

/// The binary under test (Cargo builds it for integration tests).
pub const BIN: &str = env!("CARGO_BIN_EXE_topomech");

/// A fresh empty directory `group/name` under Cargo's per-test temporary directory (whatever a
/// previous run left there is removed first).
pub fn fresh_dir(group: &str, name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(group).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs the binary with `args` in `dir` and waits for it.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(BIN).current_dir(dir).args(args).output().expect("the topomech binary runs")
}

/// `bytes` as text, invalid UTF-8 replaced.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Writes a Gmsh MSH 2.2 file of `points` and 0-based `tets` (node and element tags from 1).
pub fn write_msh(path: &Path, points: &[[f64; 3]], tets: &[[u32; 4]]) {
    let mut s = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n");
    s += &format!("{}\n", points.len());
    for (k, p) in points.iter().enumerate() {
        s += &format!("{} {:e} {:e} {:e}\n", k + 1, p[0], p[1], p[2]);
    }
    s += &format!("$EndNodes\n$Elements\n{}\n", tets.len());
    for (k, t) in tets.iter().enumerate() {
        s += &format!("{} 4 2 0 0 {} {} {} {}\n", k + 1, t[0] + 1, t[1] + 1, t[2] + 1, t[3] + 1);
    }
    s += "$EndElements\n";
    std::fs::write(path, s).unwrap();
}

/// Waits for `child` (spawned with piped stdout and stderr) at most a minute: its output, or
/// `None` when it still runs then (blocked on its input, say), after killing it.
pub fn wait_at_most_a_minute(mut child: Child) -> Option<Output> {
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Some(child.wait_with_output().unwrap())
}

/// Writes two tets that meet only at point 0 (file node tag 1: a pinched point, two vertices of
/// the map there), in either order of the tets.
pub fn write_bowtie(path: &Path, swapped: bool) {
    let points = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [-0.3, 0.0, 0.0],
        [0.0, -0.3, 0.0],
        [0.0, 0.0, -0.3],
    ];
    let mut tets = vec![[0, 1, 2, 3], [0, 5, 4, 6]];
    if swapped {
        tets.reverse();
    }
    write_msh(path, &points, &tets);
}
