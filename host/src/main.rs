//! `treelet`: build BVHs and (soon) render, on the GPU or the CPU.
use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand, ValueEnum};
use treelet::cpu_runner::CpuBackend;
use treelet::gpu::{GpuBackend, GpuContext};
use treelet::report::{run_build, BuildReport};
use treelet::scene::Scene;

mod bench;

#[derive(Parser)]
#[command(name = "treelet", version, about = "GPU BVH construction (Karras 2012) and optimization, in Rust")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Device {
    Gpu,
    Cpu,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Builder {
    Lbvh,
}

#[derive(Subcommand)]
enum Command {
    /// Build a BVH over a scene, check it, and report its cost and stage times.
    Build {
        /// Scene: random:N[:SEED] (N spheres in the Cornell box).
        #[arg(long, default_value = "random:100000")]
        scene: String,
        #[arg(long, value_enum, default_value = "lbvh")]
        builder: Builder,
        #[arg(long, value_enum, default_value = "gpu")]
        device: Device,
        /// Print one JSON object instead of a summary.
        #[arg(long)]
        json: bool,
    },
    /// Benchmarks (medians over repeats; GPU stage times from timestamp queries).
    Bench {
        #[command(subcommand)]
        what: bench::BenchCommand,
    },
}

fn print_summary(r: &BuildReport) {
    println!("scene      {} ({} primitives)", r.scene, r.primitives);
    println!("device     {} ({})", r.device, r.adapter);
    println!("builder    {}: {} nodes, SAH {:.3}", r.builder, r.nodes, r.sah_cost);
    println!("valid      {}", r.valid);
    for e in &r.errors {
        println!("  error: {e}");
    }
    let stages: Vec<String> = r.ms.iter().map(|(k, v)| format!("{k} {:.3}", v.as_f64().unwrap_or(0.0))).collect();
    println!("time       {:.3} ms ({}; {})", r.total_ms, r.timing, stages.join(", "));
}

fn run(cli: Cli) -> Result<bool> {
    match cli.command {
        Command::Build { scene, builder: Builder::Lbvh, device, json } => {
            let scene = Scene::from_spec(&scene)?;
            let (_, report) = match device {
                Device::Gpu => run_build(&mut GpuBackend::new(GpuContext::new()?), &scene)?,
                Device::Cpu => run_build(&mut CpuBackend::new(), &scene)?,
            };
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                print_summary(&report);
            }
            Ok(report.valid)
        }
        Command::Bench { what } => bench::run(what).map(|_| true),
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => {
            eprintln!("error: the built tree failed validation");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
