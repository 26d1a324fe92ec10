//! tev's TCP protocol (the viewer pbrt and Mitsuba users run): the render opens an image in
//! tev and updates it band by band, every channel of the beauty and the layers named as in
//! EXR (`R`, `G`, `B`, `albedo.R`, ...). Each packet is its length (u32, the 4 bytes
//! included), its type (u8) and its fields: little-endian integers, NUL-terminated strings,
//! float32 pixels.

use super::snapshot::Snapshot;
use super::{Budget, FilmSink, RenderProgress};
use crate::error::Error;
use crate::render::Film;
use std::io::Write;
use std::net::{TcpStream, ToSocketAddrs};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Packet types of tev's protocol that glint sends.
pub const TEV_CREATE_IMAGE: u8 = 4;
pub const TEV_UPDATE_IMAGE_V3: u8 = 6;
/// Floats per update packet at most (tev reads packets into a buffer it grows as needed;
/// bands keep each one a few MiB).
const MAX_FLOATS_PER_PACKET: usize = 1 << 20;
const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);
const WRITE_TIMEOUT: Duration = Duration::from_secs(10);

/// Sends the film to a running tev.
pub struct TevSink {
    name: String,
    conn: Mutex<Connection>,
    budget: Budget,
}

struct Connection {
    stream: Option<TcpStream>,
    /// Why the connection was given up (the render goes on without it).
    error: Option<String>,
    created: bool,
}

impl TevSink {
    /// Connects to tev at `addr` (HOST:PORT; tev listens on 127.0.0.1:14158 by default).
    /// `name` is the image's name in tev.
    pub fn connect(addr: &str, name: &str) -> Result<TevSink, Error> {
        let fail = |e: String| Error::new(format!("--tev {addr}: {e}"));
        let target =
            addr.to_socket_addrs().map_err(|e| fail(e.to_string()))?.next().ok_or_else(|| fail("no address".into()))?;
        let stream =
            TcpStream::connect_timeout(&target, CONNECT_TIMEOUT).map_err(|e| fail(format!("cannot connect: {e}")))?;
        let _ = stream.set_write_timeout(Some(WRITE_TIMEOUT));
        let _ = stream.set_nodelay(true);
        Ok(TevSink {
            name: name.to_string(),
            conn: Mutex::new(Connection { stream: Some(stream), error: None, created: false }),
            budget: Budget::default(),
        })
    }

    /// Why updates stopped, if the connection failed.
    pub fn error(&self) -> Option<String> {
        self.conn.lock().unwrap_or_else(|e| e.into_inner()).error.clone()
    }

    fn send(&self, film: &Film, progress: &RenderProgress) {
        let mut guard = self.conn.lock().unwrap_or_else(|e| e.into_inner());
        let c = &mut *guard;
        let Some(stream) = c.stream.as_mut() else { return };
        let t = Instant::now();
        let snap = Snapshot::of(film, progress);
        let names = channel_names(&snap);
        let mut result = Ok(());
        if !c.created {
            result = stream.write_all(&create_image(&self.name, snap.width, snap.height, &names));
        }
        if result.is_ok() {
            result = update_bands(stream, &self.name, &snap, &names);
        }
        match result {
            Ok(()) => c.created = true,
            Err(e) => {
                c.error = Some(format!("tev: connection lost ({e}); the render goes on without it"));
                c.stream = None;
            }
        }
        self.budget.spend(t.elapsed());
    }
}

impl FilmSink for TevSink {
    fn started(&self, _film: &Film) {
        self.budget.restart();
    }

    fn pass_done(&self, film: &Film, progress: &RenderProgress) {
        if self.budget.allows() {
            self.send(film, progress);
        }
    }

    fn finished(&self, film: &Film, progress: &RenderProgress) {
        self.send(film, progress);
    }
}

/// The channels sent, in order: the beauty's R, G, B, then each layer's (EXR names).
fn channel_names(snap: &Snapshot) -> Vec<String> {
    snap.layers.iter().flat_map(|l| l.channel_names.iter().cloned()).collect()
}

fn packet(kind: u8, body: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let mut p = vec![0u8; 4];
    p.push(kind);
    body(&mut p);
    let n = p.len() as u32;
    p[..4].copy_from_slice(&n.to_le_bytes());
    p
}

fn put_str(p: &mut Vec<u8>, s: &str) {
    // tev reads NUL-terminated strings: a NUL inside a name would cut it short.
    p.extend(s.bytes().filter(|&b| b != 0));
    p.push(0);
}

fn create_image(name: &str, width: usize, height: usize, channels: &[String]) -> Vec<u8> {
    packet(TEV_CREATE_IMAGE, |p| {
        p.push(1); // grab focus
        put_str(p, name);
        p.extend((width as i32).to_le_bytes());
        p.extend((height as i32).to_le_bytes());
        p.extend((channels.len() as i32).to_le_bytes());
        for c in channels {
            put_str(p, c);
        }
    })
}

/// Sends the image in bands of whole rows, every channel interleaved per pixel.
fn update_bands(stream: &mut TcpStream, name: &str, snap: &Snapshot, channels: &[String]) -> std::io::Result<()> {
    let nc = channels.len();
    let rows = (MAX_FLOATS_PER_PACKET / (snap.width * nc).max(1)).max(1);
    let mut y0 = 0;
    while y0 < snap.height {
        let y1 = (y0 + rows).min(snap.height);
        let pkt = packet(TEV_UPDATE_IMAGE_V3, |p| {
            p.push(0); // grab focus
            put_str(p, name);
            p.extend((nc as i32).to_le_bytes());
            for c in channels {
                put_str(p, c);
            }
            for v in [0, y0 as i32, snap.width as i32, (y1 - y0) as i32] {
                p.extend(v.to_le_bytes());
            }
            for c in 0..nc {
                p.extend((c as i64).to_le_bytes());
            }
            for _ in 0..nc {
                p.extend((nc as i64).to_le_bytes());
            }
            for i in y0 * snap.width..y1 * snap.width {
                for l in &snap.layers {
                    for v in &l.data[i * l.channels..(i + 1) * l.channels] {
                        p.extend(v.to_le_bytes());
                    }
                }
            }
        });
        stream.write_all(&pkt)?;
        y0 = y1;
    }
    stream.flush()
}
