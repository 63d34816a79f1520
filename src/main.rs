//! `topomech`: build n-G-maps from tetrahedral meshes and report what they are.
//!
//! ```text
//! topomech                       surgical demo scene on the built-in liver mesh, writes out/
//! topomech demo [--mesh F] …     the same (--out DIR, --steps N, --json)
//! topomech info MESH [--json]    characteristics of a mesh file
//! topomech simulate MESH …       mass/spring simulation (see --help)
//! topomech bench step MESH       map-driven vs flat-array step time
//! topomech refine MESH …         adaptive 1→8 refinement around a point (see --help)
//! topomech conformance generate DIR | check FILE_OR_DIR   conformance vectors (docs/CONFORMANCE.md)
//! ```
//!
//! Exit status 0 on success, 1 with one line `topomech: error: …` on stderr when the input is bad
//! (the message names the file and, when the reader knows it, the line), 2 for a bad command line.
//! `check` and `conformance check` have statuses of their own (see their `--help`): a verdict
//! is never lost to a failed write of the report.

mod cli;

use std::io::Write;
use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

use cli::CliError;

/// Verification-first n-dimensional generalized maps for topology-based simulation.
#[derive(Debug, Parser)]
#[command(name = "topomech", version, about, long_about = None)]
struct Cli {
    /// The subcommand; without one, `topomech` runs the demo.
    #[command(subcommand)]
    command: Option<Command>,
}

/// The subcommands. To add one: a variant here, an arm in [`Command::run`], and
/// `pub mod x;` in `src/cli/mod.rs` with `pub fn run(args: XArgs) -> Result<(), CliError>`.
#[derive(Debug, Subcommand)]
enum Command {
    /// The surgical scene on the built-in liver (or --mesh): sag, incision, tear, removal, refinement (the default).
    Demo(cli::demo::DemoArgs),
    /// Load a mesh file into a 3-G-map and print its characteristics.
    Info(cli::info::InfoArgs),
    /// Cut a mesh at random on a g-map and an indexed model side by side; find maps that share an adjacency graph.
    Ambiguity(cli::ambiguity::AmbiguityArgs),
    /// Run the mass/spring simulation of a mesh (frames for ParaView, JSON summary).
    Simulate(cli::simulate::SimulateArgs),
    /// Benchmarks: `bench step MESH` (map-driven vs flat-array steps), `bench order MESH` (point orders, 1 vs 2 threads).
    Bench(cli::bench_step::BenchArgs),
    /// Cut a body along a plane (face separation) and report before/after.
    Cut(cli::cut::CutArgs),
    /// Remove tets by id or inside a ball and report before/after.
    Remove(cli::cut::RemoveArgs),
    /// Simulate a hanging body that tears where its stress exceeds a threshold.
    Tear(cli::cut::TearArgs),
    /// Refine the tets meeting a ball 1→8, level by level, sharing their masses (seed 004).
    Refine(cli::refine::RefineArgs),
    /// Validate a `.tmap`/`.tmapb` map file and list each broken law (exit 0 valid, 1 broken, 2 unreadable,
    /// 3 valid but the report could not be written to stdout).
    Check(cli::check::CheckArgs),
    /// Conformance vectors: `generate DIR` writes the standard set, `check FILE_OR_DIR` replays (exit 1 mismatch, 2 unreadable).
    Conformance(cli::conformance::ConformanceArgs),
}

impl Command {
    fn run(self) -> Result<(), CliError> {
        match self {
            Command::Demo(args) => cli::demo::run(args),
            Command::Info(args) => cli::info::run(args),
            Command::Ambiguity(args) => cli::ambiguity::run(args),
            Command::Simulate(args) => cli::simulate::run(args),
            Command::Bench(args) => cli::bench_step::run(args),
            Command::Cut(args) => cli::cut::run(args),
            Command::Remove(args) => cli::cut::run_remove(args),
            Command::Tear(args) => cli::cut::run_tear(args),
            Command::Check(args) => cli::check::run(args),
            Command::Refine(args) => cli::refine::run(args),
            Command::Conformance(args) => cli::conformance::run(args),
        }
    }
}

/// `cmd` with every single-valued option that takes negative numbers (`allow_negative_numbers`)
/// also taking values that start with a hyphen, in every subcommand: clap's test for a negative
/// number misses `-1e-4` and `-.5`, which then read as unknown flags (`unexpected argument '-1'`)
/// instead of reaching the option's own value check. A comma list (`--cuts 1,5`, `--pin`,
/// `--tets`, declared with `value_delimiter` and `allow_negative_numbers`) is one value per
/// occurrence, so it is single-valued here too: `--cuts -1` reaches the count check and
/// `--cuts 5 --json` still reads `--json` as a flag. A flag written where the value belongs
/// (`--dt --json`, `--cuts --json`) is then that value, refused by the check. An option taking
/// several values per occurrence is left alone (it would swallow the flags after it).
/// O(arguments).
fn hyphen_numbers(cmd: clap::Command) -> clap::Command {
    cmd.mut_args(|arg| {
        let single = arg.get_num_args().is_none_or(|n| n.max_values() <= 1);
        match arg.is_allow_negative_numbers_set() && single {
            true => arg.allow_hyphen_values(true),
            false => arg,
        }
    })
    .mut_subcommands(hyphen_numbers)
}

/// The command line, parsed with [`hyphen_numbers`]; a usage error exits with status 2.
fn parse() -> Cli {
    let matches = hyphen_numbers(Cli::command()).get_matches();
    Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
}

fn main() -> ExitCode {
    let cli = parse();
    let command = cli.command.unwrap_or_else(|| Command::Demo(cli::demo::DemoArgs::default()));
    match command.run() {
        Ok(()) => ExitCode::SUCCESS,
        // `topomech info x | head`: the reader went away; nothing left to report.
        Err(CliError::Output(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "topomech: error: {e}");
            ExitCode::FAILURE
        }
    }
}
