//! The `tezgah` command line: wires the library stages to files and the terminal.
//!
//! Every command is a thin shell over a library call; see the README for the commands.

mod access;
mod cam;
mod cam_tool;
mod diagnostics;
mod export;
mod library;
mod panel;
mod plot;
mod preview;
mod replay;
mod run;
mod run_probe;
mod run_synced;
mod serve;
mod tracking;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use library::Inputs;
use miette::{IntoDiagnostic, Result};
use tezgah_gcode::sources::{self, Pass, Sources};
use tezgah_gcode::{Canon, CanonSink, Config, Interpreter, Origin};

#[derive(Parser)]
#[command(name = "tezgah", version, about = "CNC motion control and CAM")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the canonical machining calls of a program, as LinuxCNC's `rs274` prints them.
    Canon {
        /// The G-code program.
        program: PathBuf,
        #[command(flatten)]
        inputs: Inputs,
    },
    /// Pre-flight: check a whole program and report every error, or a short summary.
    Check {
        /// The G-code program.
        program: PathBuf,
        /// Also build the path for this machine (built-in name or file) and check that every
        /// move is within its reach and joint limits.
        #[arg(long)]
        machine: Option<String>,
        #[command(flatten)]
        inputs: Inputs,
    },
    /// Plan and run a program on a machine model: samples, report, plots and a summary.
    Run(run::RunArgs),
    /// Finishing tool path on a surface, post-processed for a table-tilting machine and
    /// verified by a dexel simulation of the cut.
    Cam(cam::CamArgs),
    /// Write a program in joint coordinates for a controller without kinematics: G1 moves
    /// split to stay within the tolerance, feeds in inverse time (G93).
    Export(export::ExportArgs),
    /// List the built-in machine definitions.
    Machines,
    /// Run the executor behind a WebSocket (JSON commands in, replies and status out).
    Serve(serve::ServeArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Error text wraps at the terminal's width on a terminal, and not at all into a pipe or a
    // log, where a message broken across lines defeats `grep`.
    let _ = miette::set_hook(Box::new(|_| {
        use std::io::IsTerminal;
        Box::new(
            miette::MietteHandlerOpts::new()
                .wrap_lines(std::io::stderr().is_terminal())
                .build(),
        )
    }));
    let result = match cli.command {
        Command::Canon { program, inputs } => canon(&program, &inputs),
        Command::Check {
            program,
            machine,
            inputs,
        } => check(&program, machine.as_deref(), &inputs),
        Command::Run(args) => run::run(args),
        Command::Cam(args) => cam::cam(args),
        Command::Export(args) => export::export(args),
        Command::Machines => run::machines().map(|()| ExitCode::SUCCESS),
        Command::Serve(args) => serve::serve(args),
    };
    match result {
        Ok(code) => code,
        Err(report) => {
            eprintln!("{report:?}");
            ExitCode::FAILURE
        }
    }
}

/// `tezgah canon`: one call per line; on error the calls made so far, then the error.
fn canon(program: &Path, inputs: &Inputs) -> Result<ExitCode> {
    let text = library::read_text(program)?;
    // As `rs274`: tool table and stored offsets in inches.
    let extra = inputs.program_inputs(Some(program))?;
    let config = Config {
        subroutines: extra.subroutines.clone(),
        ini: extra.ini.clone(),
        parameters: extra.parameters.clone(),
        ..Config::linuxcnc(library::load_tool_table(inputs.tool_table.as_deref())?)
    };
    let mut interp = Interpreter::new(config);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let mut sink = Printer { out: &mut out };
    let result = interp.run(&text, &mut sink);
    // rs274's driver resets the interpreter twice when it stops, whatever the outcome.
    sink.call(Origin::default(), Canon::OnReset);
    sink.call(Origin::default(), Canon::OnReset);
    use std::io::Write;
    out.flush().into_diagnostic()?;
    match result {
        Ok(()) => Ok(ExitCode::SUCCESS),
        Err(e) => {
            let sources = Sources::new(program.display().to_string(), text)
                .with_subroutines(&interp, |name| extra.locate(name));
            eprintln!("{:?}", diagnostics::report(&sources, &e));
            Ok(ExitCode::FAILURE)
        }
    }
}

struct Printer<'a, W: std::io::Write> {
    out: &'a mut W,
}

impl<W: std::io::Write> tezgah_gcode::CanonSink for Printer<'_, W> {
    fn call(&mut self, _origin: Origin, call: Canon) {
        // A closed pipe (`| head`) is not an error worth reporting.
        let _ = writeln!(self.out, "{call}");
    }
}

/// `tezgah check`: every error with its place, or a summary of the program. The program is
/// interpreted once; with a machine, its moves go on to the path and the machine's pre-flight.
fn check(program: &Path, machine: Option<&str>, inputs: &Inputs) -> Result<ExitCode> {
    let text = library::read_text(program)?;
    let mut counts = diagnostics::Counts::default();
    // As `run`: the machine's units (mm) for the tool table and the stored offsets.
    let extra = inputs.program_inputs(Some(program))?;
    let machine = machine.map(|m| run::load_machine(Some(m))).transpose()?;
    let config = Config {
        tool_table: library::load_tool_table(inputs.tool_table.as_deref())?,
        subroutines: extra.subroutines.clone(),
        ini: extra.ini.clone(),
        parameters: extra.parameters.clone(),
        tool_centre_point_always: machine
            .as_ref()
            .is_some_and(|m| m.tcp == tezgah_kinematics::TcpSwitch::Always),
        // Without a machine, all six axes, as LinuxCNC's `rs274`.
        axes: machine
            .as_ref()
            .map_or(tezgah_gcode::AxisMask::XYZABC, |m| {
                tezgah_gcode::AxisMask::of(m.program_axes())
            }),
        ..Config::default()
    };
    let pass = match machine {
        Some(_) => Pass::CheckMoves,
        None => Pass::Check,
    };
    let done = sources::interpret(
        Sources::new(program.display().to_string(), text),
        config,
        pass,
        |name| extra.locate(name),
        &mut counts,
    );
    if done.errors.is_empty() {
        for w in &done.warnings {
            eprintln!("warning: {w}");
        }
        if let Some(machine) = &machine {
            let tolerance = machine.motion.tolerance_mm;
            run::build_path(
                &done.sources,
                &done.keys,
                done.moves,
                machine,
                tolerance,
                tezgah_geom::Pose::ZERO,
            )?;
            println!("{}: OK on {}, {counts}", program.display(), machine.name);
            return Ok(ExitCode::SUCCESS);
        }
        println!("{}: OK, {counts}", program.display());
        return Ok(ExitCode::SUCCESS);
    }
    for e in &done.errors {
        eprintln!("{:?}", diagnostics::report(&done.sources, e));
    }
    let n = done.errors.len();
    eprintln!(
        "{}: {n} error{}",
        program.display(),
        if n == 1 { "" } else { "s" }
    );
    Ok(ExitCode::FAILURE)
}
