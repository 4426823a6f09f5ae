//! Who may open a connection to `tezgah serve`: the rules checked on every WebSocket
//! handshake, as plain functions of the request's headers so they are tested alone.
//!
//! - A browser always sends `Origin`; it must be the server's own page (`http://` + the
//!   `Host` the request was sent to), so another web site open in the same browser cannot
//!   drive the machine. A request without `Origin` comes from a script, not a page.
//! - On loopback the `Host` must name a loopback address (`localhost`, `127.x.x.x`, `[::1]`)
//!   and the listening port: a page of `evil.example.com` re-pointed at 127.0.0.1 (DNS
//!   rebinding) sends `Host: evil.example.com:…` with a matching `Origin`, and is refused.
//! - Off loopback (or with `--require-token`) every connection presents the token, in the
//!   URL (`?token=…`, which is how a browser page can pass it) or as
//!   `Authorization: Bearer …`; the comparison takes the same time wherever it differs.

use std::net::{IpAddr, SocketAddr};

/// The server's side of the rules.
#[derive(Debug, Clone)]
pub struct Access {
    /// The address listened on.
    pub addr: SocketAddr,
    /// Required on every connection when `Some`.
    pub token: Option<String>,
}

/// The parts of a handshake request the rules read.
#[derive(Debug, Default, Clone, Copy)]
pub struct Asked<'a> {
    pub host: Option<&'a str>,
    pub origin: Option<&'a str>,
    /// The request target (`/?token=…`).
    pub target: &'a str,
    pub authorization: Option<&'a str>,
}

/// Whether the token is needed: off loopback always, on loopback when asked for.
pub fn needs_token(addr: &SocketAddr, require: bool) -> bool {
    require || !addr.ip().is_loopback()
}

/// A fresh token: 128 random bits from the system's generator, as 32 hex digits.
pub fn new_token() -> Result<String, String> {
    use std::io::Read;
    let mut bytes = [0u8; 16];
    std::fs::File::open("/dev/urandom")
        .and_then(|mut f| f.read_exact(&mut bytes))
        .map_err(|e| format!("cannot read /dev/urandom for a token ({e}); use --token-file"))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// The token in a file: its first line, trimmed; at least 16 characters.
pub fn read_token(path: &std::path::Path) -> Result<String, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read the token file {}: {e}", path.display()))?;
    let token = text.lines().next().unwrap_or("").trim().to_owned();
    if token.chars().count() < 16 {
        return Err(format!(
            "the token in {} is {} characters long; it needs at least 16",
            path.display(),
            token.chars().count()
        ));
    }
    Ok(token)
}

impl Access {
    /// `Ok` when the request may connect, else the reason (sent back with a 403).
    pub fn check(&self, asked: &Asked) -> Result<(), String> {
        self.check_host(asked.host)?;
        if let Some(origin) = asked.origin {
            let own = asked.host.map(|h| format!("http://{h}"));
            if own.as_deref() != Some(origin.trim_end_matches('/')) {
                return Err(format!(
                    "Origin {origin:?} is not this server's page; only the panel served here may connect"
                ));
            }
        }
        if let Some(token) = &self.token {
            let given = query_token(asked.target).or_else(|| {
                asked
                    .authorization
                    .and_then(|a| a.strip_prefix("Bearer "))
                    .map(str::trim)
            });
            match given {
                Some(g) if same(g.as_bytes(), token.as_bytes()) => {}
                Some(_) => return Err("wrong token".into()),
                None => {
                    return Err(
                        "a token is required: add ?token=… to the URL (printed when the server started)"
                            .into(),
                    )
                }
            }
        }
        Ok(())
    }

    /// On loopback, the `Host` header must name a loopback address and the port (the pages
    /// are checked so too).
    pub fn check_host(&self, host: Option<&str>) -> Result<(), String> {
        if self.addr.ip().is_loopback() {
            let host = host.ok_or("no Host header")?;
            if !self.loopback_host(host) {
                return Err(format!(
                    "Host {host:?} is not this server's loopback address"
                ));
            }
        }
        Ok(())
    }

    /// `host[:port]` names a loopback address and the port listened on.
    fn loopback_host(&self, host: &str) -> bool {
        let (name, port) = match host.rsplit_once(':') {
            Some((n, p)) if !p.contains(']') => (n, p.parse::<u16>().ok()),
            _ => (host, Some(80)),
        };
        if port != Some(self.addr.port()) {
            return false;
        }
        let name = name.trim_start_matches('[').trim_end_matches(']');
        name.eq_ignore_ascii_case("localhost")
            || name
                .parse::<IpAddr>()
                .map(|ip| ip.is_loopback())
                .unwrap_or(false)
    }
}

/// The `token` parameter of a request target's query.
fn query_token(target: &str) -> Option<&str> {
    let (_, query) = target.split_once('?')?;
    query.split('&').find_map(|kv| kv.strip_prefix("token="))
}

/// Equal, in a time that depends on the lengths only.
fn same(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |d, (x, y)| d | (x ^ y)) == 0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn access(addr: &str, token: Option<&str>) -> Access {
        Access {
            addr: addr.parse().unwrap(),
            token: token.map(str::to_owned),
        }
    }

    #[test]
    fn off_loopback_needs_a_token_and_loopback_only_when_asked() {
        assert!(needs_token(&"0.0.0.0:7878".parse().unwrap(), false));
        assert!(needs_token(&"192.168.1.5:7878".parse().unwrap(), false));
        assert!(needs_token(&"[::]:7878".parse().unwrap(), false));
        assert!(!needs_token(&"127.0.0.1:7878".parse().unwrap(), false));
        assert!(!needs_token(&"[::1]:7878".parse().unwrap(), false));
        assert!(needs_token(&"127.0.0.1:7878".parse().unwrap(), true));
    }

    #[test]
    fn origin_must_be_the_servers_own_page() {
        let a = access("127.0.0.1:7878", None);
        let ok = |host, origin| {
            a.check(&Asked {
                host: Some(host),
                origin,
                target: "/",
                authorization: None,
            })
        };
        assert!(ok("127.0.0.1:7878", None).is_ok(), "a script");
        assert!(ok("127.0.0.1:7878", Some("http://127.0.0.1:7878")).is_ok());
        assert!(ok("localhost:7878", Some("http://localhost:7878")).is_ok());
        assert!(ok("[::1]:7878", Some("http://[::1]:7878")).is_ok());
        let e = ok("127.0.0.1:7878", Some("http://evil.example.com")).unwrap_err();
        assert!(e.contains("evil.example.com"), "{e}");
        assert!(ok("127.0.0.1:7878", Some("http://localhost:7878")).is_err());
        assert!(ok("127.0.0.1:7878", Some("null")).is_err());
        // DNS rebinding: the names match each other but not loopback.
        let e = ok(
            "evil.example.com:7878",
            Some("http://evil.example.com:7878"),
        )
        .unwrap_err();
        assert!(e.contains("loopback"), "{e}");
        // Another port is another origin.
        assert!(ok("127.0.0.1:9999", None).is_err());
        assert!(a
            .check(&Asked {
                target: "/",
                ..Asked::default()
            })
            .is_err());
    }

    #[test]
    fn the_token_is_checked_from_the_query_or_the_header() {
        let a = access("0.0.0.0:7878", Some("0123456789abcdef0123"));
        let check = |target, authorization| {
            a.check(&Asked {
                host: Some("10.0.0.2:7878"),
                origin: None,
                target,
                authorization,
            })
        };
        assert!(check("/?token=0123456789abcdef0123", None).is_ok());
        assert!(check("/?a=1&token=0123456789abcdef0123", None).is_ok());
        assert!(check("/", Some("Bearer 0123456789abcdef0123")).is_ok());
        assert!(check("/", None).unwrap_err().contains("token is required"));
        assert_eq!(check("/?token=0123", None).unwrap_err(), "wrong token");
        assert_eq!(
            check("/?token=0123456789abcdef0124", None).unwrap_err(),
            "wrong token"
        );
        // Off loopback any Host is fine, the Origin still has to match it.
        assert!(a
            .check(&Asked {
                host: Some("10.0.0.2:7878"),
                origin: Some("http://evil.example.com"),
                target: "/?token=0123456789abcdef0123",
                authorization: None,
            })
            .is_err());
    }

    #[test]
    fn tokens_are_fresh_and_files_are_checked() {
        let (a, b) = (new_token().unwrap(), new_token().unwrap());
        assert_eq!(a.len(), 32);
        assert_ne!(a, b);
        let dir = std::env::temp_dir().join(format!("tezgah-token-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("t");
        std::fs::write(&f, "  abcdefghijklmnopq  \nrest\n").unwrap();
        assert_eq!(read_token(&f).unwrap(), "abcdefghijklmnopq");
        std::fs::write(&f, "short\n").unwrap();
        assert!(read_token(&f).unwrap_err().contains("at least 16"));
        assert!(read_token(&dir.join("missing")).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
