//! The browser preview: an HTTP server on its own threads serving one page (`page.html`,
//! plain HTML, CSS and JavaScript, no external requests). The page listens to `/events`
//! (server-sent events: progress after passes, a frame number when the film was copied),
//! draws `/frame.png` (the layer it shows, tone-mapped here), asks `/pixel` under the
//! cursor and `/stop` for the Stop button. Only GET is answered; the server listens on
//! loopback unless given another address.

use super::http::{read_request, respond, respond_status, Request, READ_TIMEOUT};
use super::snapshot::{Snapshot, ToneMap, View};
use super::{Budget, FilmSink, RenderProgress};
use crate::error::Error;
use crate::render::Film;
use serde::Serialize;
use std::hash::{BuildHasher, Hasher};
use std::io::Write;
use std::net::{SocketAddr, TcpListener, TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

const PAGE: &str = include_str!("page.html");
/// Connections served at once; more are answered 503 (a page uses two or three).
const MAX_CONNECTIONS: usize = 64;
/// A comment sent on an idle event stream, so a client gone away is noticed.
const KEEPALIVE: Duration = Duration::from_secs(10);
/// Progress events at most this often (frames are rarer: they follow the budget).
const PROGRESS_INTERVAL: Duration = Duration::from_millis(250);
const WRITE_TIMEOUT: Duration = Duration::from_secs(10);

/// One worker's share of a distributed render, shown in a table on the page.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct WorkerProgress {
    pub name: String,
    /// Tasks (tiles × pass ranges) done and given.
    pub done: u64,
    pub total: u64,
    pub status: String,
}

/// A running preview server; dropping it stops listening.
pub struct PreviewServer {
    shared: Arc<Shared>,
    addr: SocketAddr,
}

struct Shared {
    state: Mutex<State>,
    changed: Condvar,
    stop: AtomicBool,
    shutdown: AtomicBool,
    watchers: AtomicUsize,
    connections: AtomicUsize,
    budget: Budget,
    /// Proves a Stop request came from the page this server served.
    token: String,
    title: String,
}

#[derive(Default)]
struct State {
    /// Bumped by every event.
    version: u64,
    /// Bumped by every new snapshot.
    frame: u64,
    snapshot: Option<Arc<Snapshot>>,
    progress: RenderProgress,
    workers: Vec<WorkerProgress>,
    last_progress: Option<Instant>,
    /// The last PNG encoded, for the next client that asks for the same.
    png: Option<(PngKey, Arc<Vec<u8>>)>,
}

#[derive(Clone, PartialEq)]
struct PngKey {
    frame: u64,
    layer: String,
    exposure: u32,
    view: View,
}

impl PreviewServer {
    /// Listens on `addr` ("HOST:PORT", or a bare port on loopback); by default on
    /// 127.0.0.1 at a free port. `title` names the render on the page.
    pub fn start(addr: Option<&str>, title: &str) -> Result<PreviewServer, Error> {
        let spec = match addr {
            None => "127.0.0.1:0".to_string(),
            Some(a) if a.parse::<u16>().is_ok() => format!("127.0.0.1:{a}"),
            Some(a) => a.to_string(),
        };
        let addrs: Vec<SocketAddr> = spec
            .to_socket_addrs()
            .map_err(|e| Error::new(format!("preview address {spec}: {e} (give HOST:PORT or PORT)")))?
            .collect();
        let listener =
            TcpListener::bind(&addrs[..]).map_err(|e| Error::new(format!("preview: cannot listen on {spec}: {e}")))?;
        let addr = listener.local_addr().map_err(|e| Error::new(format!("preview: {e}")))?;
        let shared = Arc::new(Shared {
            state: Mutex::new(State::default()),
            changed: Condvar::new(),
            stop: AtomicBool::new(false),
            shutdown: AtomicBool::new(false),
            watchers: AtomicUsize::new(0),
            connections: AtomicUsize::new(0),
            budget: Budget::default(),
            token: random_token(),
            title: title.to_string(),
        });
        let s = shared.clone();
        std::thread::Builder::new()
            .name("glint-preview".into())
            .spawn(move || accept_loop(listener, s))
            .map_err(|e| Error::new(format!("preview: cannot start its thread: {e}")))?;
        Ok(PreviewServer { shared, addr })
    }

    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    /// Open event streams (pages watching).
    pub fn watchers(&self) -> usize {
        self.shared.watchers.load(Ordering::SeqCst)
    }

    /// Copies the film for the page now, whatever the budget (after a render, or for a film
    /// assembled elsewhere: a render farm's merged film).
    pub fn publish(&self, film: &Film, progress: &RenderProgress) {
        let snap = Snapshot::of(film, progress);
        self.shared.update(|s| {
            s.frame += 1;
            s.snapshot = Some(Arc::new(snap));
            s.progress = progress.clone();
        });
    }

    /// Sets the progress figures without copying the film.
    pub fn set_progress(&self, progress: &RenderProgress) {
        self.shared.update(|s| s.progress = progress.clone());
    }

    /// Sets the per-worker table of a distributed render.
    pub fn set_workers(&self, workers: Vec<WorkerProgress>) {
        self.shared.update(|s| s.workers = workers);
    }

    /// Frames copied for pages so far, and the time copying and encoding them took (what the
    /// render paid: encoding counted as 1/cores, as it runs beside the render's threads).
    pub fn cost(&self) -> (u64, Duration) {
        (self.shared.lock().frame, self.shared.budget.spent())
    }

    /// Lets the Stop button be pressed again (a new render on the same page).
    pub fn clear_stop(&self) {
        self.shared.stop.store(false, Ordering::SeqCst);
    }
}

impl FilmSink for PreviewServer {
    fn started(&self, _film: &Film) {
        self.shared.budget.restart();
    }

    fn pass_done(&self, film: &Film, progress: &RenderProgress) {
        let budget = &self.shared.budget;
        if self.watchers() > 0 && budget.allows() {
            let t = Instant::now();
            let snap = Snapshot::of(film, progress);
            budget.spend(t.elapsed());
            self.shared.update(|s| {
                s.frame += 1;
                s.snapshot = Some(Arc::new(snap));
                s.progress = progress.clone();
                s.last_progress = Some(Instant::now());
            });
            return;
        }
        let mut s = self.shared.lock();
        if s.last_progress.is_none_or(|t| t.elapsed() >= PROGRESS_INTERVAL) {
            s.progress = progress.clone();
            s.last_progress = Some(Instant::now());
            s.version += 1;
            self.shared.changed.notify_all();
        }
    }

    fn finished(&self, film: &Film, progress: &RenderProgress) {
        // The last frame, for the pages watching (a front end that keeps the page up after
        // the render, Python's, publishes it itself when none watches).
        if self.watchers() == 0 {
            return self.set_progress(progress);
        }
        let t = Instant::now();
        self.publish(film, progress);
        self.shared.budget.spend(t.elapsed());
    }

    fn stop_requested(&self) -> bool {
        self.shared.stop.load(Ordering::SeqCst)
    }
}

impl Drop for PreviewServer {
    fn drop(&mut self) {
        self.shared.shutdown.store(true, Ordering::SeqCst);
        self.shared.changed.notify_all();
        // Wakes the accept loop so that it sees the shutdown.
        let mut wake = self.addr;
        if wake.ip().is_unspecified() {
            wake.set_ip(if wake.is_ipv4() { [127, 0, 0, 1].into() } else { std::net::Ipv6Addr::LOCALHOST.into() });
        }
        let _ = TcpStream::connect_timeout(&wake, Duration::from_millis(200));
    }
}

impl Shared {
    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn update(&self, f: impl FnOnce(&mut State)) {
        let mut s = self.lock();
        f(&mut s);
        s.version += 1;
        self.changed.notify_all();
    }

    /// The event the page receives: progress, layers, the frame to fetch, the workers.
    fn event_json(&self, s: &State) -> String {
        let layers: Vec<serde_json::Value> = s
            .snapshot
            .iter()
            .flat_map(|snap| &snap.layers)
            .map(|l| serde_json::json!({"name": l.name, "kind": l.kind}))
            .collect();
        let (w, h) = s.snapshot.as_ref().map_or((0, 0), |snap| (snap.width, snap.height));
        serde_json::json!({
            "title": self.title,
            "frame": s.frame,
            "width": w,
            "height": h,
            "layers": layers,
            "progress": s.progress,
            "workers": s.workers,
        })
        .to_string()
    }
}

fn random_token() -> String {
    // RandomState is seeded from the OS's randomness once per process, then per instance.
    let a = std::collections::hash_map::RandomState::new().build_hasher().finish();
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(a);
    format!("{a:016x}{:016x}", h.finish())
}

fn accept_loop(listener: TcpListener, shared: Arc<Shared>) {
    for conn in listener.incoming() {
        if shared.shutdown.load(Ordering::SeqCst) {
            break;
        }
        let Ok(mut stream) = conn else { continue };
        let _ = stream.set_write_timeout(Some(WRITE_TIMEOUT));
        if shared.connections.fetch_add(1, Ordering::SeqCst) >= MAX_CONNECTIONS {
            shared.connections.fetch_sub(1, Ordering::SeqCst);
            respond_status(&mut stream, 503, "too many connections");
            continue;
        }
        let s = shared.clone();
        let spawned = std::thread::Builder::new().name("glint-preview-conn".into()).spawn(move || {
            handle(&s, stream);
            s.connections.fetch_sub(1, Ordering::SeqCst);
        });
        if spawned.is_err() {
            shared.connections.fetch_sub(1, Ordering::SeqCst);
        }
    }
}

fn handle(shared: &Shared, mut stream: TcpStream) {
    let _ = stream.set_read_timeout(Some(READ_TIMEOUT));
    let req = match read_request(&mut stream) {
        Ok(r) => r,
        Err(status) => return respond_status(&mut stream, status, "not an HTTP/1.1 request"),
    };
    if req.method != "GET" {
        return respond_status(&mut stream, 405, "this server answers GET only");
    }
    match req.path.as_str() {
        "/" => {
            let page = PAGE.replace("__TOKEN__", &shared.token).replace("__TITLE__", &html_escape(&shared.title));
            respond(&mut stream, 200, "text/html; charset=utf-8", page.as_bytes())
        }
        "/state" => {
            let body = shared.event_json(&shared.lock());
            respond(&mut stream, 200, "application/json", body.as_bytes())
        }
        "/events" => events(shared, stream),
        "/frame.png" => frame(shared, &req, &mut stream),
        "/pixel" => pixel(shared, &req, &mut stream),
        "/stop" => {
            if req.param("token") != Some(shared.token.as_str()) {
                return respond_status(&mut stream, 403, "a stop must come from the page");
            }
            shared.stop.store(true, Ordering::SeqCst);
            respond(&mut stream, 200, "text/plain; charset=utf-8", b"stopping after this pass\n")
        }
        _ => respond_status(&mut stream, 404, "no such page"),
    }
}

/// Server-sent events: one `data:` line of JSON each time the state changes.
fn events(shared: &Shared, mut stream: TcpStream) {
    shared.watchers.fetch_add(1, Ordering::SeqCst);
    let head = "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nCache-Control: no-store\r\n\r\n";
    let mut seen = u64::MAX;
    let mut ok = stream.write_all(head.as_bytes()).is_ok();
    while ok && !shared.shutdown.load(Ordering::SeqCst) {
        let msg = {
            let s = shared.lock();
            let (s, _) = shared
                .changed
                .wait_timeout_while(s, KEEPALIVE, |s| s.version == seen && !shared.shutdown.load(Ordering::SeqCst))
                .unwrap_or_else(|e| e.into_inner());
            if s.version == seen {
                ": keep-alive\n\n".to_string()
            } else {
                seen = s.version;
                format!("data: {}\n\n", shared.event_json(&s))
            }
        };
        ok = stream.write_all(msg.as_bytes()).and_then(|_| stream.flush()).is_ok();
    }
    shared.watchers.fetch_sub(1, Ordering::SeqCst);
}

fn frame(shared: &Shared, req: &Request, stream: &mut TcpStream) {
    let layer = req.param("layer").unwrap_or("beauty");
    let exposure = req.param("exposure").and_then(|e| e.parse::<f32>().ok()).filter(|e| e.is_finite());
    let view = View::parse(req.param("view").unwrap_or("srgb"));
    let (Some(exposure), Some(view)) = (exposure.or(Some(0.0)).map(|e| e.clamp(-20.0, 20.0)), view) else {
        return respond_status(stream, 400, "view is srgb, linear or false");
    };
    let (snap, frame_no, cached) = {
        let s = shared.lock();
        let Some(snap) = s.snapshot.clone() else { return respond_status(stream, 404, "no pass has landed yet") };
        let key = PngKey { frame: s.frame, layer: layer.to_string(), exposure: exposure.to_bits(), view };
        let cached = s.png.as_ref().filter(|(k, _)| *k == key).map(|(_, png)| png.clone());
        (snap, s.frame, cached)
    };
    if let Some(png) = cached {
        return respond(stream, 200, "image/png", &png);
    }
    let Some(l) = snap.layer(layer) else { return respond_status(stream, 404, "the render has no such layer") };
    let t = Instant::now();
    let rgb = snap.tone_map(l, ToneMap { exposure, view });
    let png = match encode_png(&rgb, snap.width, snap.height) {
        Ok(p) => Arc::new(p),
        Err(e) => return respond_status(stream, 500, &e),
    };
    // Encoding runs beside the render's threads: it takes 1/cores of their throughput.
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as u32;
    shared.budget.spend(t.elapsed() / cores);
    shared.lock().png =
        Some((PngKey { frame: frame_no, layer: layer.to_string(), exposure: exposure.to_bits(), view }, png.clone()));
    respond(stream, 200, "image/png", &png)
}

fn pixel(shared: &Shared, req: &Request, stream: &mut TcpStream) {
    let coord = |n| req.param(n).and_then(|v| v.parse::<usize>().ok());
    let (Some(x), Some(y)) = (coord("x"), coord("y")) else {
        return respond_status(stream, 400, "give x and y");
    };
    let snap = shared.lock().snapshot.clone();
    match snap.and_then(|s| s.pixel_json(x, y)) {
        Some(body) => respond(stream, 200, "application/json", body.as_bytes()),
        None => respond_status(stream, 404, "no such pixel (yet)"),
    }
}

fn encode_png(rgb: &[u8], width: usize, height: usize) -> Result<Vec<u8>, String> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    let enc = image::codecs::png::PngEncoder::new_with_quality(
        &mut out,
        image::codecs::png::CompressionType::Fast,
        image::codecs::png::FilterType::Sub,
    );
    enc.write_image(rgb, width as u32, height as u32, image::ExtendedColorType::Rgb8).map_err(|e| e.to_string())?;
    Ok(out)
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
