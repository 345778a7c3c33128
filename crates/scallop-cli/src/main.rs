//! `scallop`: the command-line program. Parses arguments, reads and writes
//! files, shows progress, maps failures to exit codes (0 ok, 1 job rejected,
//! 2 I/O or internal error). All the work is done by the libraries.

mod analyze;
mod choice;
mod drop;
mod engagement;
mod guides;
mod input;
mod machine;
mod optimize;
mod output;
mod outset;
mod part;
mod pocket;
mod post;
mod render;
mod rough5;
mod rough5_job;
mod run;
mod simulate;
mod waterline;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// How a command failed: the user's input was rejected, or the machine failed us.
#[derive(Debug)]
pub enum Failure {
    /// Bad input or an unsafe result: exit code 1.
    Rejected(anyhow::Error),
    /// I/O or internal error: exit code 2.
    Io(anyhow::Error),
}

impl Failure {
    /// A rejection with a message.
    pub fn rejected(msg: impl std::fmt::Display) -> Failure {
        Failure::Rejected(anyhow::anyhow!("{msg}"))
    }
}

/// Result of a command.
pub type CliResult<T> = Result<T, Failure>;

#[derive(Parser, Debug)]
#[command(name = "scallop", version, about = "scallop: verified, time-efficient toolpaths for free-form surfaces")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run the built-in demo: the Choi surface finished by a bull-nose at a guaranteed scallop height, proven on a simulated stock (--raster, --rough: the other demos).
    Demo(output::DemoArgs),
    /// Run a job from a job file (TOML; see docs/job.md): its roughing, rest roughing and finishing operations on one stock, simulated; program, report, toolpath.
    Run(run::RunArgs),
    /// Drop a cutter onto a part on an XY grid and write the cutter locations as CSV.
    Drop(drop::DropArgs),
    /// Analyse a part's shape (PCA) and recommend a cutter and a feed direction before any toolpath.
    Analyze(analyze::AnalyzeArgs),
    /// Cut a stock with a 3-axis G-code program and verify it against the part (gouges are errors).
    Simulate(simulate::SimulateArgs),
    /// Partition a surface into zones and optimise their directions or orientations (see docs/job.md).
    Optimize(optimize::OptimizeArgs),
    /// Post-process a cutter-location file for a machine and a dialect, with a machine-aware time report.
    Post(post::PostArgs),
    /// Render a part (and a toolpath) to a PNG picture, without a browser.
    Render(render::RenderArgs),
    /// The closed contours where a cutter with its tip at height z touches a mesh (CSV or JSON loops).
    Waterline(waterline::WaterlineArgs),
    /// Guide curves of 5-axis roughing on a test part: levels, limit, path and tilt curves (docs/guides.md).
    Guides(guides::GuidesArgs),
    /// 5-axis roughing of a test part by guide curves, proven and posted (docs/rough5.md).
    Rough5(rough5::Rough5Args),
    /// Clear a 2D pocket (region JSON: outer boundary, then islands) and write G-code and CL.
    Pocket(pocket::PocketArgs),
    /// Load a part and report what was read (size, welding, open and non-manifold edges).
    Inspect(part::InspectArgs),
    /// Measure a 2.5D pocket program's engagement, links, air cuts, uncut area and cycle time on its pocket.
    Engagement(engagement::EngagementArgs),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // Help and version go to stdout with exit 0; a bad command line is a rejected job (1).
            let code = if e.use_stderr() { 1 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let result = match cli.command {
        Command::Demo(args) => output::demo(&args),
        Command::Drop(args) => drop::run(&args),
        Command::Run(args) => run::run(&args),
        Command::Inspect(args) => part::inspect(&args),
        Command::Analyze(args) => analyze::run(&args),
        Command::Simulate(args) => simulate::run(&args),
        Command::Optimize(args) => optimize::run(&args),
        Command::Post(args) => post::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Waterline(args) => waterline::run(&args),
        Command::Guides(args) => guides::run(&args),
        Command::Rough5(args) => rough5::run(&args),
        Command::Engagement(args) => engagement::run(&args),
        Command::Pocket(args) => pocket::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Rejected(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
        Err(Failure::Io(e)) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
