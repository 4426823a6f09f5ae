//! `tezgah serve`: the executor behind a WebSocket on localhost, so the panel (served on the
//! same port, `crate::panel`) or a script can drive the machine. Each text message in is one
//! JSON command; each reply, control change and the status stream go out as JSON (schema in
//! the README). Who may connect is `crate::access`'s to say; of those connected, one drives
//! and the others watch (`Control`). The executor runs on its own threads
//! (`tezgah_executor::threads`); this module only carries messages.

use std::io::ErrorKind;
use std::net::{TcpListener, TcpStream};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use miette::{miette, IntoDiagnostic, Result, WrapErr};
use serde::Serialize;
use tezgah_executor::command::{Command, Status};
use tezgah_executor::drive::IdealDrive;
use tezgah_executor::executor::{ExecOptions, Executor};
use tezgah_executor::realtime::RealtimeSettings;
use tezgah_executor::threads::{spawn, Handle};
use tezgah_geom::Pose;
use tezgah_kinematics::Kinematics;
use tungstenite::handshake::server::{
    ErrorResponse, Request as HandshakeRequest, Response as HandshakeResponse,
};
use tungstenite::http::StatusCode;
use tungstenite::protocol::WebSocketConfig;
use tungstenite::{Message, WebSocket};

use crate::access::{needs_token, new_token, read_token, Access, Asked};

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
    /// Read the access token from this file (its first line) instead of making one up. Off
    /// loopback every connection must present the token (`?token=` in the URL, or an
    /// `Authorization: Bearer` header).
    #[arg(long)]
    pub token_file: Option<PathBuf>,
    /// Require the token on loopback too (off loopback it is always required).
    #[arg(long)]
    pub require_token: bool,
    /// The largest message accepted, MiB: a larger one is answered with an error and its
    /// connection closed (a running job goes on).
    #[arg(long, default_value_t = 16)]
    pub max_message_mib: usize,
    /// Where the set-points go: `ideal` (a simulated drive that is always where it was told)
    /// or `ethercat:<interface>`, the CiA-402 drives the machine file's `[drive]` table lists,
    /// on that network interface (needs CAP_NET_RAW; see the README).
    #[arg(long, default_value = "ideal")]
    pub drive: String,
    /// With `--drive ethercat:…`: how long a cycle waits for its frame before the machine
    /// stops on a lost frame, ms (default: 80 % of the machine's period).
    #[arg(long)]
    pub bus_timeout_ms: Option<f64>,
}

/// The drive `--drive` names, opened.
enum Bus {
    Ideal,
    Ethercat(Box<tezgah_ethercat::drive::EthercatDrive>),
}

/// Opens the drive `spec` names for `machine` (its file text `text` holds `[drive]`); a bus
/// cycle waits `bus_timeout_ms` for its frame (default: 80 % of `period`).
fn open_drive(
    spec: &str,
    machine: &tezgah_kinematics::Machine,
    text: &str,
    period: f64,
    bus_timeout_ms: Option<f64>,
) -> Result<Bus> {
    match spec.split_once(':') {
        None if spec == "ideal" => Ok(Bus::Ideal),
        Some(("ethercat", interface)) if !interface.is_empty() => {
            let section = tezgah_ethercat::DriveSection::from_machine_text(text, machine)
                .map_err(|e| miette!("{e}"))?
                .ok_or_else(|| miette!("{}", tezgah_ethercat::SectionError::Missing))?;
            let link = tezgah_ethercat::master::link::RawSocket::open(interface)
                .map_err(|e| miette!("EtherCAT on {interface}: {e}"))?;
            let mut options =
                tezgah_ethercat::master::MasterOptions::for_period(Duration::from_secs_f64(period));
            if let Some(ms) = bus_timeout_ms {
                if !(ms.is_finite() && ms > 0.0 && ms <= 1000.0) {
                    return Err(miette!(
                        "--bus-timeout-ms must be > 0 and at most 1000, got {ms}"
                    ));
                }
                options.cycle_timeout = Duration::from_secs_f64(ms / 1000.0);
            }
            let drive = tezgah_ethercat::drive::EthercatDrive::open(
                Box::new(link),
                &section,
                machine.joints.len(),
                options,
            )
            .map_err(|e| miette!("EtherCAT on {interface}: {e}"))?;
            Ok(Bus::Ethercat(Box::new(drive)))
        }
        _ => Err(miette!(
            "--drive {spec}: expected `ideal` or `ethercat:<interface>`"
        )),
    }
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
        /// What a query asked for (`preview`).
        #[serde(skip_serializing_if = "Option::is_none")]
        data: Option<serde_json::Value>,
    },
    /// Sent first: the machine, for the panel's readout, jog buttons and travel box.
    Hello { machine: &'a serde_json::Value },
    /// The periodic status.
    Status(StatusOut<'a>),
    /// Who holds control: sent on connecting and to every client whenever it changes.
    Control {
        /// This connection's number.
        client: u64,
        /// The connection in control, if any.
        holder: Option<u64>,
        /// This connection is in control.
        you: bool,
    },
}

/// The executor's status and, on a machine with rotary joints, the tool axis.
#[derive(Debug, Serialize)]
struct StatusOut<'a> {
    #[serde(flatten)]
    status: &'a Status,
    /// Unit vector tip → spindle in the workpiece frame (the preview's frame).
    #[serde(skip_serializing_if = "Option::is_none")]
    tool_axis: Option<[f64; 3]>,
    /// With a drive bus: each drive's state, actual position and error, in bus order.
    #[serde(skip_serializing_if = "Option::is_none")]
    drives: Option<Vec<tezgah_ethercat::monitor::DriveReading>>,
}

/// One client holds control at a time; the others watch. The first to connect while nobody
/// holds it gets it; `take_control` takes it from whoever holds it (both are told);
/// `release_control` or closing the connection frees it.
#[derive(Default)]
struct Control {
    holder: Mutex<Option<u64>>,
    /// Bumped at every change, so each session knows when to announce it.
    generation: AtomicU64,
    next_client: AtomicU64,
}

impl Control {
    fn holder(&self) -> Option<u64> {
        *self.holder.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn set(&self, f: impl FnOnce(&mut Option<u64>)) {
        let mut h = self.holder.lock().unwrap_or_else(|e| e.into_inner());
        let before = *h;
        f(&mut h);
        if *h != before {
            self.generation.fetch_add(1, Ordering::SeqCst);
        }
    }
}

/// Points at most in a preview (a longer program's preview is cut short, and says so).
const PREVIEW_POINTS: usize = 400_000;

/// What the sessions share.
struct Shared {
    /// The machine as the `hello` message describes it.
    machine: serde_json::Value,
    /// Its kinematics when it has rotary joints (for the tool axis in the status).
    kinematics: Option<tezgah_kinematics::Model>,
    host: Handle,
    /// The drive bus' monitor, when there is a bus.
    drives: Option<Arc<tezgah_ethercat::monitor::Monitor>>,
    control: Control,
    access: Access,
    interval: Duration,
    max_message: usize,
}

/// Runs the server until the process is stopped.
pub fn serve(args: ServeArgs) -> Result<std::process::ExitCode> {
    let machine = crate::run::load_machine(args.machine.as_deref())?;
    let text = crate::run::machine_text(args.machine.as_deref())?;
    let options = ExecOptions::for_machine(&machine);
    let period = options.period;
    if !(args.lead_ms.is_finite() && args.lead_ms > 0.0) {
        return Err(miette!("--lead-ms must be > 0, got {}", args.lead_ms));
    }
    if args.max_message_mib == 0 || args.max_message_mib > 1024 {
        return Err(miette!(
            "--max-message-mib must be 1 to 1024, got {}",
            args.max_message_mib
        ));
    }
    let listener = TcpListener::bind(&args.listen)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot listen on {}", args.listen))?;
    let addr = listener.local_addr().into_diagnostic()?;
    let token = match (&args.token_file, needs_token(&addr, args.require_token)) {
        (Some(path), _) => Some(read_token(path).map_err(|e| miette!("{e}"))?),
        (None, true) => Some(new_token().map_err(|e| miette!("{e}"))?),
        (None, false) => None,
    };
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
    let bus = open_drive(&args.drive, &machine, &text, period, args.bus_timeout_ms)?;
    let drives = match &bus {
        Bus::Ideal => None,
        Bus::Ethercat(d) => Some(d.monitor()),
    };
    let host = match bus {
        Bus::Ideal => spawn(executor, IdealDrive, ring, realtime),
        Bus::Ethercat(drive) => {
            // The machine starts where the executor stands; drives elsewhere would jump.
            let (at, start) = (drive.position(), executor.drive_joints());
            let off = at
                .as_slice()
                .iter()
                .zip(start.as_slice())
                .any(|(a, b)| (a - b).abs() > 1e-3);
            if off {
                return Err(miette!(
                    "the drives stand at {:?}, the machine starts at {:?} (internal units): \
                     move them to the start first",
                    at.as_slice(),
                    start.as_slice()
                ));
            }
            log(&format!(
                "EtherCAT: {} drives in operation enabled",
                drive.master().slaves().len()
            ));
            spawn(executor, *drive, ring, realtime)
        }
    };
    for w in host.realtime.warnings() {
        log(&format!("warning: {w}"));
    }

    // The first line tells a script (or a test started with port 0) where to connect; all
    // lines go out in one write, and a closed stdout is no reason to stop.
    let query = token
        .as_ref()
        .map(|t| format!("?token={t}"))
        .unwrap_or_default();
    let mut banner = format!(
        "tezgah serve: machine {}, listening on ws://{addr}\n",
        machine.name
    );
    if token.is_some() {
        banner += "tezgah serve: every connection needs the token: ?token=… in the URL or an Authorization: Bearer header\n";
    }
    banner += &format!("tezgah serve: the panel is at http://{addr}/{query}\n");
    {
        use std::io::Write;
        let mut out = std::io::stdout().lock();
        let _ = out.write_all(banner.as_bytes());
        let _ = out.flush();
    }
    let shared = Arc::new(Shared {
        machine: describe(&machine, period),
        kinematics: machine
            .joints
            .iter()
            .any(|j| j.kind == tezgah_kinematics::JointKind::Rotary)
            .then(|| machine.kinematics.clone()),
        host,
        drives,
        control: Control::default(),
        access: Access { addr, token },
        interval: Duration::from_millis(args.status_ms.max(1)),
        max_message: args.max_message_mib << 20,
    });
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let shared = Arc::clone(&shared);
        std::thread::spawn(move || {
            if let Err(e) = session(stream, &shared) {
                log(&format!("connection closed: {e}"));
            }
        });
    }
    Ok(std::process::ExitCode::SUCCESS)
}

/// One client: the handshake's checks, then commands in, replies, control changes and the
/// status stream out, until it closes.
fn session(stream: TcpStream, shared: &Shared) -> Result<(), String> {
    // A client that never finishes its handshake does not hold a thread for ever.
    stream
        .set_read_timeout(Some(Duration::from_secs(10)))
        .map_err(|e| e.to_string())?;
    // The panel's pages on the same port: anything but a WebSocket handshake.
    let head = crate::panel::peek_head(&stream)?;
    if !crate::panel::is_upgrade(&head.text) {
        return crate::panel::respond(stream, &head, &shared.access);
    }
    // The refusal's type is tungstenite's (its `Callback` trait), large or not.
    #[allow(clippy::result_large_err)]
    let check = |request: &HandshakeRequest, response: HandshakeResponse| {
        let header = |name: &str| request.headers().get(name).and_then(|v| v.to_str().ok());
        let target = request
            .uri()
            .path_and_query()
            .map(|p| p.as_str())
            .unwrap_or("/");
        let asked = Asked {
            host: header("host"),
            origin: header("origin"),
            target,
            authorization: header("authorization"),
        };
        match shared.access.check(&asked) {
            Ok(()) => Ok(response),
            Err(reason) => {
                log(&format!("refused a connection: {reason}"));
                let mut refusal = ErrorResponse::new(Some(format!("refused: {reason}\n")));
                *refusal.status_mut() = StatusCode::FORBIDDEN;
                Err(refusal)
            }
        }
    };
    let config = WebSocketConfig::default()
        .max_message_size(Some(shared.max_message))
        .max_frame_size(Some(shared.max_message));
    let mut ws = match tungstenite::accept_hdr_with_config(stream, check, Some(config)) {
        Ok(ws) => ws,
        // A refusal was logged with its reason by `check`.
        Err(tungstenite::HandshakeError::Failure(tungstenite::Error::Http(_))) => return Ok(()),
        Err(e) => return Err(e.to_string()),
    };
    // Reads wait at most a little, so the status stream keeps its pace.
    ws.get_mut()
        .set_read_timeout(Some(Duration::from_millis(5)))
        .map_err(|e| e.to_string())?;
    let me = shared.control.next_client.fetch_add(1, Ordering::SeqCst) + 1;
    shared.control.set(|h| {
        if h.is_none() {
            *h = Some(me)
        }
    });
    let result = session_loop(&mut ws, shared, me);
    shared.control.set(|h| {
        if *h == Some(me) {
            *h = None
        }
    });
    result
}

fn session_loop(ws: &mut WebSocket<TcpStream>, shared: &Shared, me: u64) -> Result<(), String> {
    let control = &shared.control;
    send(
        ws,
        &Outgoing::Hello {
            machine: &shared.machine,
        },
    )?;
    let mut announced = None;
    let mut next_status = Instant::now();
    loop {
        let generation = control.generation.load(Ordering::SeqCst);
        if announced != Some(generation) {
            announced = Some(generation);
            let holder = control.holder();
            send(
                ws,
                &Outgoing::Control {
                    client: me,
                    holder,
                    you: holder == Some(me),
                },
            )?;
        }
        match ws.read() {
            Ok(Message::Text(text)) => {
                let reply = answer(shared, me, text.as_str());
                send(ws, &reply)?;
            }
            Ok(Message::Binary(_)) => send(
                ws,
                &refusal("binary messages are not commands; send JSON text"),
            )?,
            Ok(Message::Close(_)) => return Ok(()),
            Ok(_) => {}
            Err(tungstenite::Error::Io(e))
                if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(tungstenite::Error::ConnectionClosed | tungstenite::Error::AlreadyClosed) => {
                return Ok(())
            }
            // The frame was read whole: the stream is still in step.
            Err(tungstenite::Error::Utf8(_)) => {
                send(ws, &refusal("a text message that is not UTF-8"))?
            }
            Err(tungstenite::Error::Capacity(e)) => {
                // The rest of the message is still on its way and cannot be told from the
                // next: answer, close (1009), and read and drop what comes until the client
                // closes, so the answer is not lost to a reset.
                let reason = format!(
                    "message too large: {e}; the limit is {} MiB (--max-message-mib); closing this connection",
                    shared.max_message >> 20
                );
                send(ws, &refusal(&reason))?;
                let _ = ws.close(Some(tungstenite::protocol::CloseFrame {
                    code: tungstenite::protocol::frame::coding::CloseCode::Size,
                    reason: "message too large".into(),
                }));
                drain(ws.get_mut());
                return Err(reason);
            }
            Err(e) => {
                let reason = format!("{e}; closing this connection");
                let _ = send(ws, &refusal(&reason));
                return Err(reason);
            }
        }
        if Instant::now() >= next_status {
            next_status += shared.interval;
            let status = shared
                .host
                .status
                .lock()
                .map(|s| s.clone())
                .map_err(|_| "the executor has stopped".to_owned())?;
            let tool_axis = shared.kinematics.as_ref().and_then(|k| {
                let q = tezgah_kinematics::Joints::from_slice(&status.joints).ok()?;
                let pose = k
                    .forward(&q, &tezgah_kinematics::Tool::with_length(0.0))
                    .ok()?;
                Some([pose.axis.x, pose.axis.y, pose.axis.z])
            });
            send(
                ws,
                &Outgoing::Status(StatusOut {
                    status: &status,
                    tool_axis,
                    drives: shared.drives.as_ref().map(|m| m.readings()),
                }),
            )?;
        }
    }
}

/// Reads and drops what arrives until the peer closes, goes quiet for a second or 10 s pass.
fn drain(stream: &mut TcpStream) {
    use std::io::Read;
    let _ = stream.set_read_timeout(Some(Duration::from_secs(1)));
    let end = Instant::now() + Duration::from_secs(10);
    let mut buf = vec![0u8; 64 << 10];
    while Instant::now() < end {
        match stream.read(&mut buf) {
            Ok(0) | Err(_) => return,
            Ok(_) => {}
        }
    }
}

fn refusal(reason: &str) -> Outgoing<'static> {
    Outgoing::Reply {
        id: None,
        ok: false,
        error: Some(reason.to_owned()),
        data: None,
    }
}

/// The reply to one text message from client `me`.
fn answer(shared: &Shared, me: u64, text: &str) -> Outgoing<'static> {
    let value = match serde_json::from_str::<serde_json::Value>(text) {
        Ok(v) => v,
        Err(e) => return refusal(&format!("not a command: {e}")),
    };
    let id = value.get("id").and_then(|v| v.as_u64());
    let mut data = None;
    let result = match value.get("command").and_then(|c| c.as_str()) {
        // A query, not a command: watchers may ask too.
        Some("preview") => {
            let moves = shared.host.program.lock().ok().and_then(|p| p.clone());
            let start = shared.host.status.lock().map(|s| s.tip).unwrap_or([0.0; 3]);
            match moves {
                None => Err("no program loaded".to_owned()),
                Some(moves) => {
                    let start = Pose::new(start[0], start[1], start[2], 0.0, 0.0, 0.0);
                    let (pieces, cut) = crate::preview::pieces(start, &moves, PREVIEW_POINTS);
                    data = Some(serde_json::json!({"pieces": pieces, "cut": cut}));
                    Ok(())
                }
            }
        }
        Some("take_control") => {
            shared.control.set(|h| *h = Some(me));
            Ok(())
        }
        Some("release_control") => {
            shared.control.set(|h| {
                if *h == Some(me) {
                    *h = None
                }
            });
            Ok(())
        }
        _ => match serde_json::from_value::<Command>(value) {
            Err(e) => Err(format!("not a command: {e}")),
            Ok(request) => match shared.control.holder() {
                Some(h) if h == me => shared
                    .host
                    .request(request)
                    .map_err(|e| e.to_string()),
                holder => Err(format!(
                    "this connection (client {me}) is watching: {}; send {{\"command\": \"take_control\"}} first",
                    match holder {
                        Some(h) => format!("client {h} holds control"),
                        None => "nobody holds control".to_owned(),
                    }
                )),
            },
        },
    };
    Outgoing::Reply {
        id,
        ok: result.is_ok(),
        error: result.err(),
        data,
    }
}

fn send(ws: &mut WebSocket<TcpStream>, message: &Outgoing) -> Result<(), String> {
    let text = serde_json::to_string(message).map_err(|e| e.to_string())?;
    ws.send(Message::text(text)).map_err(|e| e.to_string())
}

/// A line on stderr; a closed stderr is no reason to stop.
fn log(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr().lock(), "tezgah serve: {line}");
}

/// The machine for the panel: name, period and each joint's name, unit, travel and limits.
fn describe(machine: &tezgah_kinematics::Machine, period: f64) -> serde_json::Value {
    let joints: Vec<serde_json::Value> = machine
        .joints
        .iter()
        .map(|j| {
            let unit = if j.to_internal() == 1.0 { "mm" } else { "deg" };
            let finite = |v: f64| v.is_finite().then_some(v);
            serde_json::json!({
                "name": j.name,
                "unit": unit,
                "min": finite(j.min),
                "max": finite(j.max),
                "max_velocity": j.max_velocity,
                "max_acceleration": j.max_acceleration,
                "max_jerk": j.max_jerk,
            })
        })
        .collect();
    serde_json::json!({"name": machine.name, "period_s": period, "joints": joints})
}
