//! `tezgah serve`: the executor behind a WebSocket on localhost, so a panel or a script can
//! drive the machine. Each text message in is one JSON command; each reply and the status
//! stream go out as JSON (schema in the README). The executor runs on its own threads
//! (`tezgah_executor::threads`); this module only carries messages.

use std::io::ErrorKind;
use std::net::{TcpListener, TcpStream};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use miette::{miette, IntoDiagnostic, Result, WrapErr};
use serde::{Deserialize, Serialize};
use tezgah_executor::command::{Command, Status};
use tezgah_executor::drive::IdealDrive;
use tezgah_executor::executor::{ExecOptions, Executor};
use tezgah_executor::realtime::RealtimeSettings;
use tezgah_executor::threads::{spawn, Handle};
use tezgah_geom::Pose;
use tungstenite::{Message, WebSocket};

/// Options of `tezgah serve`.
#[derive(clap::Args)]
pub struct ServeArgs {
    /// A built-in machine name (see `tezgah machines`) or a machine file.
    #[arg(long)]
    pub machine: Option<String>,
    /// Address to listen on (port 0 picks a free port; the first line printed names it).
    #[arg(long, default_value = "127.0.0.1:7878")]
    pub listen: String,
    /// Set-points kept ahead of the real-time thread (the ring's length), ms: more rides out a
    /// busy computer, less makes hold and override act sooner.
    #[arg(long, default_value_t = 32.0)]
    pub lead_ms: f64,
    /// Interval of the status stream, ms.
    #[arg(long, default_value_t = 50)]
    pub status_ms: u64,
    /// Leave the real-time thread time-shared: no SCHED_FIFO, no memory lock (by default
    /// both are asked for, best effort, with a warning when the system refuses).
    #[arg(long)]
    pub no_realtime: bool,
    /// A folder of subroutine files `<name>.ngc` for loaded programs and MDI (repeatable;
    /// a loaded program arrives as text, so it has no folder of its own).
    #[arg(long = "subroutine-path")]
    pub subroutine_path: Vec<PathBuf>,
}

/// A message from a client: a command with an optional id that its reply echoes.
#[derive(Debug, Deserialize)]
struct Request {
    #[serde(default)]
    id: Option<u64>,
    #[serde(flatten)]
    command: Command,
}

/// What the server sends.
#[derive(Debug, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
enum Outgoing<'a> {
    /// The answer to one request.
    Reply {
        id: Option<u64>,
        ok: bool,
        #[serde(skip_serializing_if = "Option::is_none")]
        error: Option<String>,
    },
    /// The periodic status.
    Status(&'a Status),
}

/// Runs the server until the process is stopped.
pub fn serve(args: ServeArgs) -> Result<std::process::ExitCode> {
    let machine = crate::run::load_machine(args.machine.as_deref())?;
    let options = ExecOptions::for_machine(&machine).map_err(|e| miette!("{e}"))?;
    let period = options.period;
    if !(args.lead_ms.is_finite() && args.lead_ms > 0.0) {
        return Err(miette!("--lead-ms must be > 0, got {}", args.lead_ms));
    }
    let ring = ((args.lead_ms / 1000.0 / period).ceil() as usize).max(2);
    let mut executor = Executor::new(&machine, options, Pose::ZERO).map_err(|e| miette!("{e}"))?;
    let inputs = crate::library::program_inputs(None, None, None, &args.subroutine_path)?;
    if let Some(library) = inputs.subroutines {
        executor = executor.with_subroutines(library);
    }
    // Shared by the connections: each request waits for its own answer only.
    let realtime = if args.no_realtime {
        RealtimeSettings::OFF
    } else {
        RealtimeSettings::BEST_EFFORT
    };
    let host = Arc::new(spawn(executor, IdealDrive, ring, realtime));
    for w in host.realtime.warnings() {
        eprintln!("tezgah serve: warning: {w}");
    }

    let listener = TcpListener::bind(&args.listen)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot listen on {}", args.listen))?;
    let addr = listener.local_addr().into_diagnostic()?;
    // The first line tells a script (or a test started with port 0) where to connect.
    println!(
        "tezgah serve: machine {}, listening on ws://{addr}",
        machine.name
    );
    use std::io::Write;
    let _ = std::io::stdout().flush();
    let interval = Duration::from_millis(args.status_ms.max(1));
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let host = Arc::clone(&host);
        std::thread::spawn(move || {
            if let Err(e) = session(stream, &host, interval) {
                eprintln!("tezgah serve: connection closed: {e}");
            }
        });
    }
    Ok(std::process::ExitCode::SUCCESS)
}

/// One client: commands in, replies and the status stream out, until it closes.
fn session(stream: TcpStream, host: &Handle, interval: Duration) -> Result<(), String> {
    let mut ws = tungstenite::accept(stream).map_err(|e| e.to_string())?;
    // Reads wait at most a little, so the status stream keeps its pace.
    ws.get_mut()
        .set_read_timeout(Some(Duration::from_millis(5)))
        .map_err(|e| e.to_string())?;
    let mut next_status = Instant::now();
    loop {
        match ws.read() {
            Ok(Message::Text(text)) => {
                let reply = answer(host, text.as_str());
                send(&mut ws, &reply)?;
            }
            Ok(Message::Close(_)) => return Ok(()),
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(tungstenite::Error::ConnectionClosed | tungstenite::Error::AlreadyClosed) => {
                return Ok(())
            }
            Err(e) => return Err(e.to_string()),
        }
        if Instant::now() >= next_status {
            next_status += interval;
            let status = host
                .status
                .lock()
                .map(|s| s.clone())
                .map_err(|_| "the executor has stopped".to_owned())?;
            send(&mut ws, &Outgoing::Status(&status))?;
        }
    }
}

/// The reply to one text message.
fn answer(host: &Handle, text: &str) -> Outgoing<'static> {
    let (id, result) = match serde_json::from_str::<Request>(text) {
        Ok(request) => (
            request.id,
            host.request(request.command).map_err(|e| e.to_string()),
        ),
        Err(e) => (None, Err(format!("not a command: {e}"))),
    };
    Outgoing::Reply {
        id,
        ok: result.is_ok(),
        error: result.err(),
    }
}

fn send(ws: &mut WebSocket<TcpStream>, message: &Outgoing) -> Result<(), String> {
    let text = serde_json::to_string(message).map_err(|e| e.to_string())?;
    ws.send(Message::text(text)).map_err(|e| e.to_string())
}
