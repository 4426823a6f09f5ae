//! A WebSocket client of `tezgah serve` for the tests that drive it (`serve.rs`,
//! `serve_ethercat.rs`): messages as JSON, requests answered by their reply, statuses waited for.

use std::net::TcpStream;
use std::time::{Duration, Instant};

use serde_json::Value;
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

pub type Socket = WebSocket<MaybeTlsStream<TcpStream>>;

/// The next text message, as JSON.
pub fn next(ws: &mut Socket) -> Value {
    loop {
        if let Message::Text(t) = ws.read().unwrap() {
            return serde_json::from_str(t.as_str()).unwrap();
        }
    }
}

/// Sends a request and returns its reply (status messages in between are skipped).
pub fn request(ws: &mut Socket, message: Value) -> Value {
    ws.send(Message::text(message.to_string())).unwrap();
    loop {
        let m = next(ws);
        if m["type"] == "reply" {
            return m;
        }
    }
}

/// How long [`wait_for`] waits for a status before the test fails (wall time: a loaded
/// machine runs the server slowly).
const WAIT: Duration = Duration::from_secs(30);

/// Reads statuses until `done` holds for one (at most [`WAIT`]).
pub fn wait_for(ws: &mut Socket, done: impl Fn(&Value) -> bool) -> Value {
    let deadline = Instant::now() + WAIT;
    let mut last = Value::Null;
    loop {
        assert!(
            Instant::now() < deadline,
            "timed out waiting for a status; the last: {last}"
        );
        let m = next(ws);
        if m["type"] == "status" {
            if done(&m) {
                return m;
            }
            last = m;
        }
    }
}

/// The executor's state in a status message.
pub fn state(status: &Value) -> &str {
    status["state"]["state"].as_str().unwrap_or("")
}
