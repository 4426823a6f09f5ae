//! The `tezgah` command line: wires the library stages to files and the terminal.
//!
//! Every command is a thin shell over a library call; see the README for the commands.

mod cam;
mod diagnostics;
mod library;
mod plot;
mod run;
mod serve;
mod tracking;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use miette::{IntoDiagnostic, Result, WrapErr};
use tezgah_gcode::{Canon, CanonSink, Config, Interpreter, Origin};

#[derive(Parser)]
#[command(name = "tezgah", version, about = "CNC motion control and CAM")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// What a program may read besides its own text.
#[derive(clap::Args)]
struct Inputs {
    /// A tool table in LinuxCNC's format.
    #[arg(long)]
    tool_table: Option<PathBuf>,
    /// A folder of subroutine files `<name>.ngc` (repeatable; the program's folder first).
    #[arg(long = "subroutine-path")]
    subroutine_path: Vec<PathBuf>,
    /// A LinuxCNC INI file: its `[RS274NGC] SUBROUTINE_PATH` and `#<_ini[section]name>` values.
    #[arg(long)]
    ini: Option<PathBuf>,
    /// A LinuxCNC parameter file (`.var`): the work offsets, G92 offsets and other numbered
    /// parameters the program starts with.
    #[arg(long)]
    params: Option<PathBuf>,
}

impl Inputs {
    fn program_inputs(&self, program: Option<&Path>) -> Result<library::ProgramInputs> {
        library::program_inputs(
            program,
            self.ini.as_deref(),
            self.params.as_deref(),
            &self.subroutine_path,
        )
    }
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
    Run {
        /// The G-code program (default: the built-in demo).
        program: Option<PathBuf>,
        /// A built-in machine name (see `tezgah machines`) or a machine file.
        #[arg(long)]
        machine: Option<String>,
        /// Write every sample to this CSV file.
        #[arg(long)]
        samples: Option<PathBuf>,
        /// Write the verification report to this JSON file.
        #[arg(long)]
        report: Option<PathBuf>,
        /// Write plots (SVG and PNG) of feed and joint v/a/j into this directory.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Interpolation period, s (default: the machine file's `period_s`).
        #[arg(long)]
        period: Option<f64>,
        /// Path tolerance, mm (default: the machine file's `tolerance_mm`; G64 P overrides).
        #[arg(long)]
        tolerance: Option<f64>,
        /// The drive the samples go to: `ideal` (measured = commanded) or `servo` (the machine
        /// file's servo model; the report adds tracking RMSE, following and contour errors).
        #[arg(long, value_enum, default_value = "ideal")]
        drive: tracking::DriveKind,
        #[command(flatten)]
        inputs: Inputs,
    },
    /// Finishing tool path on a surface, post-processed for a table-tilting machine and
    /// verified by a dexel simulation of the cut.
    Cam {
        /// The surface (STEP file).
        surface: PathBuf,
        /// The cutter: ball:D, flat:D or bull:D:r (diameter D, corner radius r, mm).
        #[arg(long)]
        tool: String,
        /// zigzag, zigzag-oneway or iso-scallop.
        #[arg(long)]
        strategy: String,
        /// Largest scallop height, mm.
        #[arg(long)]
        scallop: f64,
        /// Chord and linearisation tolerance, mm.
        #[arg(long)]
        tolerance: f64,
        /// Lead angle: the tool tilted from the normal toward the feed, degrees.
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        lead: f64,
        /// Tilt angle: the tool tilted from the normal across the feed, degrees.
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        tilt: f64,
        /// Cutting feed, mm/min (the tip's speed on the part).
        #[arg(long, default_value_t = 1000.0)]
        feed: f64,
        /// Write feeds in inverse time (G93).
        #[arg(long)]
        inverse_time: bool,
        /// Write machine joints (G43, no tool-centre-point control) instead of G43.4 output.
        #[arg(long)]
        joints: bool,
        /// A table-tilting machine: built-in name or file (default table-ac).
        #[arg(long)]
        machine: Option<String>,
        /// The program to write.
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
        /// Write the report JSON here.
        #[arg(long)]
        report: Option<PathBuf>,
        /// A tool table in LinuxCNC's format (the tool's length).
        #[arg(long)]
        tool_table: Option<PathBuf>,
        /// The tool number for T and H words.
        #[arg(long, default_value_t = 1)]
        tool_number: u32,
        /// The STEP `#id` of the face to machine (needed when the file has several faces).
        #[arg(long)]
        face: Option<u64>,
        /// The most the tool axis may lean from the part's +Z, degrees: contact points facing
        /// further away are left out (default: 75°, or less if the machine's tilt range is).
        #[arg(long)]
        max_tilt: Option<f64>,
        /// Dexel spacing of the verifying simulation, mm (default: a twentieth of the
        /// step-over; coarser is faster and widens the reported grid bound).
        #[arg(long)]
        verify_cell: Option<f64>,
    },
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
        Command::Run {
            program,
            machine,
            samples,
            report,
            plot,
            period,
            tolerance,
            drive,
            inputs,
        } => run::run(run::RunArgs {
            program,
            machine,
            samples,
            report,
            plot,
            period,
            tolerance,
            drive,
            tool_table: inputs.tool_table,
            subroutine_path: inputs.subroutine_path,
            ini: inputs.ini,
            params: inputs.params,
        }),
        Command::Cam {
            surface,
            tool,
            strategy,
            scallop,
            tolerance,
            lead,
            tilt,
            feed,
            inverse_time,
            joints,
            machine,
            output,
            report,
            tool_table,
            tool_number,
            face,
            max_tilt,
            verify_cell,
        } => cam::cam(cam::CamArgs {
            surface,
            tool,
            strategy,
            scallop,
            tolerance,
            lead_deg: lead,
            tilt_deg: tilt,
            feed,
            inverse_time,
            joints,
            machine,
            output,
            report,
            tool_table,
            tool_number,
            face,
            max_tilt_deg: max_tilt,
            verify_cell_mm: verify_cell,
        }),
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

fn read_text(path: &Path) -> Result<String> {
    std::fs::read(path)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot read {}", path.display()))
        .map(|bytes| String::from_utf8_lossy(&bytes).into_owned())
}

/// `tezgah canon`: one call per line; on error the calls made so far, then the error.
fn canon(program: &Path, inputs: &Inputs) -> Result<ExitCode> {
    let text = read_text(program)?;
    // As `rs274`: tool table and stored offsets in inches.
    let extra = inputs.program_inputs(Some(program))?;
    let config = Config {
        subroutines: extra.subroutines,
        ini: extra.ini,
        parameters: extra.parameters,
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
            eprintln!("{:?}", diagnostics::report(program, &text, &e));
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

/// `tezgah check`: every error with its place, or a summary of the program.
fn check(program: &Path, machine: Option<&str>, inputs: &Inputs) -> Result<ExitCode> {
    let text = read_text(program)?;
    let mut counts = diagnostics::Counts::default();
    // As `run`: the machine's units (mm) for the tool table and the stored offsets.
    let extra = inputs.program_inputs(Some(program))?;
    let config = Config {
        tool_table: library::load_tool_table(inputs.tool_table.as_deref())?,
        subroutines: extra.subroutines,
        ini: extra.ini,
        parameters: extra.parameters,
        ..Config::default()
    };
    let machine = machine.map(|m| run::load_machine(Some(m))).transpose()?;
    let config = Config {
        tool_centre_point_always: machine
            .as_ref()
            .is_some_and(|m| m.tcp == tezgah_kinematics::TcpSwitch::Always),
        ..config
    };
    let errors = tezgah_gcode::check_into(&text, config.clone(), &mut counts);
    if errors.is_empty() {
        if let Some(machine) = &machine {
            // The interpreter found nothing: its moves exist; the machine checks them.
            let moves = tezgah_gcode::program_moves(&text, config)
                .map_err(|e| diagnostics::report(program, &text, &e))?;
            let tolerance = machine.motion.tolerance_mm;
            run::build_path(program, &text, moves, machine, tolerance)?;
            println!("{}: OK on {}, {counts}", program.display(), machine.name);
            return Ok(ExitCode::SUCCESS);
        }
        println!("{}: OK, {counts}", program.display());
        return Ok(ExitCode::SUCCESS);
    }
    for e in &errors {
        eprintln!("{:?}", diagnostics::report(program, &text, e));
    }
    eprintln!(
        "{}: {} error{}",
        program.display(),
        errors.len(),
        if errors.len() == 1 { "" } else { "s" }
    );
    Ok(ExitCode::FAILURE)
}
