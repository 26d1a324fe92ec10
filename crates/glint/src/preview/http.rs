//! Just enough HTTP/1.1 for the preview page: one request per connection, its request line
//! and headers read with a size limit and a timeout; responses close the connection.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::Duration;

/// Longest request head read (request line and headers); longer is refused.
const MAX_HEAD_BYTES: usize = 8192;
/// A client that sends nothing for this long is dropped.
pub const READ_TIMEOUT: Duration = Duration::from_secs(5);

/// A parsed request: its method, path and query parameters.
#[derive(Debug, PartialEq)]
pub struct Request {
    pub method: String,
    pub path: String,
    pub query: Vec<(String, String)>,
}

impl Request {
    pub fn param(&self, name: &str) -> Option<&str> {
        self.query.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
    }
}

/// Reads the request head; Err(status) for a request that cannot be answered.
pub fn read_request(stream: &mut TcpStream) -> Result<Request, u16> {
    let mut head = Vec::new();
    let mut buf = [0u8; 1024];
    while !head.windows(4).any(|w| w == b"\r\n\r\n") {
        if head.len() > MAX_HEAD_BYTES {
            return Err(431);
        }
        match stream.read(&mut buf) {
            Ok(0) | Err(_) => return Err(400),
            Ok(n) => head.extend_from_slice(&buf[..n]),
        }
    }
    parse_head(&head).ok_or(400)
}

/// The request line of a head: `METHOD TARGET HTTP/1.x`.
pub fn parse_head(head: &[u8]) -> Option<Request> {
    let line = head.split(|&b| b == b'\n').next()?;
    let line = std::str::from_utf8(line).ok()?.trim_end_matches('\r');
    let mut parts = line.split(' ');
    let (method, target, version) = (parts.next()?, parts.next()?, parts.next()?);
    if parts.next().is_some()
        || !version.starts_with("HTTP/1.")
        || method.is_empty()
        || !method.bytes().all(|b| b.is_ascii_uppercase())
        || !target.starts_with('/')
    {
        return None;
    }
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    let query = query
        .split('&')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let (k, v) = p.split_once('=').unwrap_or((p, ""));
            (k.to_string(), v.to_string())
        })
        .collect();
    Some(Request { method: method.to_string(), path: path.to_string(), query })
}

/// Writes a whole response and closes the connection.
pub fn respond(stream: &mut TcpStream, status: u16, content_type: &str, body: &[u8]) {
    let head = format!(
        "HTTP/1.1 {status} {}\r\nContent-Type: {content_type}\r\nContent-Length: {}\r\nCache-Control: no-store\r\n\
         X-Content-Type-Options: nosniff\r\n{}Connection: close\r\n\r\n",
        reason(status),
        body.len(),
        if status == 405 { "Allow: GET\r\n" } else { "" },
    );
    // A client gone mid-response is no error of the render's.
    let _ = stream.write_all(head.as_bytes()).and_then(|_| stream.write_all(body)).and_then(|_| stream.flush());
}

/// Answers with a status and its reason as plain text.
pub fn respond_status(stream: &mut TcpStream, status: u16, detail: &str) {
    respond(stream, status, "text/plain; charset=utf-8", format!("{status} {}: {detail}\n", reason(status)).as_bytes());
}

fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        431 => "Request Header Fields Too Large",
        503 => "Service Unavailable",
        _ => "Error",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn request_lines_parse_and_garbage_does_not() {
        let r = parse_head(b"GET /pixel?x=3&y=4 HTTP/1.1\r\nHost: a\r\n\r\n").unwrap();
        assert_eq!((r.method.as_str(), r.path.as_str()), ("GET", "/pixel"));
        assert_eq!((r.param("x"), r.param("y"), r.param("z")), (Some("3"), Some("4"), None));
        for bad in [
            &b"\x00\xff\r\n\r\n"[..],
            b"GET\r\n\r\n",
            b"GET / HTTP/2\r\n\r\n",
            b"get / HTTP/1.1\r\n\r\n",
            b"GET x HTTP/1.1\r\n\r\n",
        ] {
            assert!(parse_head(bad).is_none(), "{:?}", String::from_utf8_lossy(bad));
        }
    }
}
