//! The `twister` command-line tool: `render`, `error`, `info` and `bench`.

// Comparisons written `!(x > y)` are deliberate: they put NaN on the rejecting side.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use std::process::ExitCode;

use twister_cli::{args, bench, flags, info, measure, render, sequence, view};

use clap::{Parser, Subcommand};

use bench::{BenchCommand, Figure};

#[derive(Parser)]
#[command(name = "twister", version, about = "Omnidirectional stereo (TWISTER concentric-mosaic) rendering on the GPU")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene into the left- and right-eye panoramas.
    Render(args::RenderArgs),
    /// Open a live window: the panoramas drawn every frame as `render` draws them; keys move the
    /// viewer and switch the method, panorama, samples and display; F12 saves the frame.
    View(view::ViewCmdArgs),
    /// Measure the display-position error of a method (seed 002 §4.1).
    Error(measure::ErrorArgs),
    /// Describe a scene file as JSON: triangles, objects, materials, bounds, cameras, lights, warnings,
    /// and a suggested viewer position.
    Info(info::InfoArgs),
    /// Benchmarks (release builds): `speed` times methods on scenes; the paper's figures; LOD.
    #[command(subcommand)]
    Bench(BenchCommand),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind::{DisplayHelp, DisplayHelpOnMissingArgumentOrSubcommand, DisplayVersion};
            if matches!(e.kind(), DisplayHelp | DisplayVersion | DisplayHelpOnMissingArgumentOrSubcommand) {
                e.exit();
            }
            // One line naming the option and the problem (clap's usage tips follow on `--help`).
            let text = e.render().to_string();
            eprintln!("{}", text.lines().next().unwrap_or("error: bad arguments"));
            return ExitCode::from(2);
        }
    };
    let result = match &cli.command {
        Command::Render(args) => match args.frames {
            Some(frames) => sequence::render_sequence(args, frames),
            None => render::render(args),
        },
        Command::View(args) => view::view(args),
        Command::Error(args) => measure::measure(args),
        Command::Info(args) => info::info(args),
        Command::Bench(BenchCommand::Speed(args)) => bench::bench_speed(args),
        Command::Bench(BenchCommand::Fig8(args)) => bench::bench_figures(args, Figure::Fig8),
        Command::Bench(BenchCommand::Fig10(args)) => bench::bench_figures(args, Figure::Fig10),
        Command::Bench(BenchCommand::Fig12(args)) => bench::bench_figures(args, Figure::Fig12),
        Command::Bench(BenchCommand::Lod(args)) => bench::bench_figures(args, Figure::Lod),
        Command::Bench(BenchCommand::TraceLod(args)) => bench::bench_figures(args, Figure::TraceLod),
        Command::Bench(BenchCommand::All(args)) => bench::bench_figures(args, Figure::All),
        Command::Bench(BenchCommand::Startup(args)) => bench::bench_startup(args),
        Command::Bench(BenchCommand::Search(args)) => bench::search::bench_search(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", flags::for_user(e));
            ExitCode::FAILURE
        }
    }
}
