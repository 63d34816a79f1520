//! Round 20, CLI leftovers of round 19: the text summary of `simulate` writes its time step in
//! exponent form where a plain decimal would run to hundreds of digits.

mod cli_common;

use cli_common::{fresh_dir, run_in, text};

const MESH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/data/liver_547_v22.msh");

/// The summary line of the steps shows the time step as the JSON does: 1e-300 s, not a
/// 302-character decimal; an ordinary step stays a plain decimal.
#[test]
fn the_simulate_summary_writes_a_tiny_time_step_in_exponent_form() {
    let dir = fresh_dir("round20_cli", "tiny_dt");
    for (dt, shown) in [("1e-300", "2 × 1e-300 s"), ("0.0005", "2 × 0.0005 s")] {
        let out = run_in(&dir, &["simulate", MESH, "--steps", "2", "--dt", dt]);
        let stdout = text(&out.stdout);
        assert!(out.status.success(), "simulate --dt {dt} failed: {}", text(&out.stderr));
        let line = stdout.lines().find(|l| l.trim_start().starts_with("steps")).expect("a steps line");
        assert!(line.contains(shown), "dt {dt}: {line:?} does not show {shown:?}");
        assert!(line.len() < 80, "dt {dt}: the steps line runs to {} bytes", line.len());
    }
}
