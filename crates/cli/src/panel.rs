//! The operator panel's files, built into the binary, and the little HTTP server that hands
//! them out on the WebSocket's port: `GET /` is the panel, the rest its scripts and style.
//! Nothing here can command the machine; the page does that over the WebSocket, which checks
//! who is asking (`crate::access`).

use std::borrow::Cow;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use crate::access::Access;

/// (path, content type, body)
const FILES: &[(&str, &str, &[u8])] = &[
    (
        "/",
        "text/html; charset=utf-8",
        include_bytes!("../panel/index.html"),
    ),
    (
        "/panel.css",
        "text/css; charset=utf-8",
        include_bytes!("../panel/panel.css"),
    ),
    (
        "/panel.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../panel/panel.js"),
    ),
    (
        "/view3d.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../panel/view3d.js"),
    ),
    (
        "/plots.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../panel/plots.js"),
    ),
];

/// The longest request head read.
const MAX_HEAD: usize = 16 << 10;

/// A request's head as peeked.
pub struct Head {
    /// The request line and headers (not UTF-8 bytes replaced).
    pub text: String,
    /// Its length on the socket, bytes.
    pub len: usize,
}

/// The request's head (request line and headers), read without taking it off the socket, so
/// a WebSocket handshake can still be read whole by tungstenite.
pub fn peek_head(stream: &TcpStream) -> Result<Head, String> {
    let mut buf = vec![0u8; MAX_HEAD];
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let n = stream.peek(&mut buf).map_err(|e| e.to_string())?;
        if n == 0 {
            return Err("closed before a request".into());
        }
        if let Some(end) = buf[..n].windows(4).position(|w| w == b"\r\n\r\n") {
            return Ok(Head {
                text: String::from_utf8_lossy(&buf[..end + 4]).into_owned(),
                len: end + 4,
            });
        }
        if n == buf.len() {
            return Err(format!("a request head longer than {MAX_HEAD} bytes"));
        }
        if Instant::now() > deadline {
            return Err("the request head did not come whole within 10 s".into());
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// A header's value in a request head (the name case-insensitive).
pub fn header<'a>(head: &'a str, name: &str) -> Option<&'a str> {
    head.lines().skip(1).find_map(|l| {
        let (k, v) = l.split_once(':')?;
        k.trim().eq_ignore_ascii_case(name).then(|| v.trim())
    })
}

/// The head asks for a WebSocket.
pub fn is_upgrade(head: &str) -> bool {
    header(head, "upgrade").is_some_and(|v| v.to_ascii_lowercase().contains("websocket"))
}

/// Answers a plain HTTP request (the head already peeked) and closes.
pub fn respond(mut stream: TcpStream, head: &Head, access: &Access) -> Result<(), String> {
    // Take the head off the socket (its body, if any, is ignored).
    let mut sink = vec![0u8; head.len];
    stream.read_exact(&mut sink).map_err(|e| e.to_string())?;
    let head = head.text.as_str();
    let mut words = head.lines().next().unwrap_or("").split_whitespace();
    let (method, target) = (words.next().unwrap_or(""), words.next().unwrap_or(""));
    let path = target.split('?').next().unwrap_or("");
    const TEXT: &str = "text/plain; charset=utf-8";
    let (status, kind, body): (&str, &str, Cow<[u8]>) =
        if let Err(reason) = access.check_host(header(head, "host")) {
            let body = format!("refused: {reason}\n").into_bytes();
            ("403 Forbidden", TEXT, Cow::Owned(body))
        } else if method != "GET" && method != "HEAD" {
            ("405 Method Not Allowed", TEXT, Cow::Borrowed(b"GET only\n"))
        } else {
            match FILES.iter().find(|(p, _, _)| *p == path) {
                Some((_, kind, body)) => ("200 OK", kind, Cow::Borrowed(*body)),
                None => ("404 Not Found", TEXT, Cow::Borrowed(b"not found\n")),
            }
        };
    let head_out = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\n\
         Cache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nX-Frame-Options: DENY\r\n\
         Content-Security-Policy: default-src 'self'; connect-src 'self'; img-src 'self' data:; style-src 'self'; frame-ancestors 'none'\r\n\
         Connection: close\r\n\r\n",
        body.len()
    );
    stream
        .write_all(head_out.as_bytes())
        .map_err(|e| e.to_string())?;
    if method != "HEAD" {
        stream.write_all(&body).map_err(|e| e.to_string())?;
    }
    stream.flush().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heads_are_read() {
        let head = "GET /?token=x HTTP/1.1\r\nHost: 127.0.0.1:1\r\nUpgrade: WebSocket\r\nConnection: Upgrade\r\n\r\n";
        assert!(is_upgrade(head));
        assert_eq!(header(head, "HOST"), Some("127.0.0.1:1"));
        assert!(!is_upgrade("GET / HTTP/1.1\r\nHost: a\r\n\r\n"));
        assert_eq!(header("GET / HTTP/1.1\r\n\r\n", "host"), None);
    }
}
