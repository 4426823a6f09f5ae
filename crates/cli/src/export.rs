//! `tezgah export`: wires gcode (interpretation, carried-through words) → tezgah-export (the
//! path as `run` builds it, written in joint coordinates) → the .ngc file and a summary.

use std::path::PathBuf;

use miette::{miette, IntoDiagnostic, Result, WrapErr};
use tezgah_export::write::Header;
use tezgah_export::{AxisLetters, PassThrough};
use tezgah_gcode::sources::{interpret, Pass, Sources};

use crate::diagnostics::report_line;
use crate::run::{load_machine, machine_config};

/// The command line of `tezgah export`.
#[derive(clap::Args)]
pub struct ExportArgs {
    /// The G-code program.
    pub program: PathBuf,
    /// A built-in machine name (see `tezgah machines`) or a machine file.
    #[arg(long)]
    pub machine: String,
    /// The joint-space program to write.
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// Path tolerance, mm (default: the machine file's `tolerance_mm`; G64 P overrides).
    #[arg(long)]
    pub tolerance: Option<f64>,
    #[command(flatten)]
    pub inputs: crate::library::Inputs,
}

pub fn export(args: ExportArgs) -> Result<std::process::ExitCode> {
    let machine = load_machine(Some(&args.machine))?;
    let letters = AxisLetters::for_machine(&machine).map_err(|e| miette!("{e}"))?;
    let text = crate::library::read_text(&args.program)?;
    let table = crate::library::load_tool_table(args.inputs.tool_table.as_deref())?;
    let extra = args.inputs.program_inputs(Some(&args.program))?;
    let config = machine_config(&machine, table, &extra);
    let tolerance = args.tolerance.unwrap_or(machine.motion.tolerance_mm);
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return Err(miette!("--tolerance must be > 0, got {tolerance}"));
    }
    let mut words = PassThrough::new();
    let done = interpret(
        Sources::new(args.program.display().to_string(), text),
        config,
        Pass::Run,
        |name| extra.locate(name),
        &mut words,
    );
    if let Some(e) = done.errors.first() {
        eprintln!("{:?}", crate::diagnostics::report(&done.sources, e));
        return Ok(std::process::ExitCode::FAILURE);
    }
    for w in &done.warnings {
        eprintln!("warning: {w}");
    }
    let placed = words.placed(&done.moves);
    let keys = &done.keys;
    let exported =
        tezgah_export::export(done.moves, &placed, &machine, tolerance, &|k| keys.plain(k))
            .map_err(|e| match e.line() {
                Some(line) => report_line(&done.sources, keys.source(line), &e.to_string()),
                None => miette!("{e}"),
            })?;
    let s = exported.summary;
    let header = Header {
        program: &args.program.display().to_string(),
        machine: &machine.name,
        mapping: letters.describe(&machine),
        budget: s.budget,
    };
    let program = tezgah_export::write::program(&exported.blocks, &letters, &header);
    std::fs::write(&args.output, program)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot write {}", args.output.display()))?;
    println!(
        "{} → {}: {} blocks in, {} out ({})",
        args.program.display(),
        args.output.display(),
        s.blocks_in,
        s.blocks_out,
        letters.describe(&machine),
    );
    if s.blocks_out == 0 {
        return Ok(std::process::ExitCode::SUCCESS);
    }
    let axis = match s.axis {
        Some((worst, budget)) => format!("; tool axis {worst:.4}° (budget {budget:.4}°)"),
        None => String::new(),
    };
    println!(
        "joint-linear deviation {:.4} mm (line {}, budget {:.4} mm of tolerance {tolerance} mm){axis}; \
         longest block {:.3} mm (line {})",
        s.worst_deviation, s.worst_line, s.budget, s.longest, s.longest_line
    );
    Ok(std::process::ExitCode::SUCCESS)
}
