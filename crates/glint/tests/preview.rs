//! Live views: the preview server binds loopback by default, answers GET only, and leaves the
//! render unharmed (the same bits) whatever its clients do: ten watching at once, one leaving
//! mid-stream, others sending garbage. Its Stop stops the render after a pass. The tev sink's
//! packets, decoded by a fake tev, carry the film's very values.

use glint::formats::ReadOptions;
use glint::preview::{FilmSink, PreviewServer, TevSink};
use glint::render::{Aov, Film, Silent};
use glint::session::{FilmOptions, RenderControl, RenderReport, Session};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

const SIZE: u32 = 24;

fn session(spp: u32) -> Session {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.json");
    let mut s = Session::open(&scene, &ReadOptions::default()).unwrap();
    let d = s.edit();
    d.film.width = SIZE;
    d.film.height = SIZE;
    d.sampler.spp = spp;
    s
}

fn render(spp: u32, sinks: &[&dyn FilmSink]) -> (Film, RenderReport) {
    let mut s = session(spp);
    let mut film = s.new_film(&FilmOptions { aovs: vec![Aov::Albedo, Aov::Depth], ..Default::default() }).unwrap();
    let cancel = AtomicBool::new(false);
    let control = RenderControl { sinks, ..RenderControl::new(&cancel, &Silent) };
    let report = s.render(&mut film, &control, &mut |_| Ok(())).unwrap();
    (film, report)
}

/// Sends raw bytes and reads the whole response (the server closes after one).
fn exchange(addr: SocketAddr, request: &[u8]) -> String {
    let mut c = TcpStream::connect(addr).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    let _ = c.write_all(request);
    let _ = c.shutdown(std::net::Shutdown::Write);
    let mut out = Vec::new();
    let _ = c.read_to_end(&mut out);
    String::from_utf8_lossy(&out).into_owned()
}

fn get(addr: SocketAddr, path: &str) -> String {
    exchange(addr, format!("GET {path} HTTP/1.1\r\nHost: x\r\n\r\n").as_bytes())
}

fn body(response: &str) -> &str {
    response.split_once("\r\n\r\n").map_or("", |(_, b)| b)
}

#[test]
fn binds_loopback_by_default_and_answers_get_only() {
    let server = PreviewServer::start(None, "test").unwrap();
    let addr = server.addr();
    assert!(addr.ip().is_loopback(), "{addr}");
    assert!(server.url().starts_with("http://127.0.0.1:"));
    for method in ["POST", "PUT", "DELETE", "HEAD", "OPTIONS", "PATCH"] {
        for path in ["/", "/events", "/stop", "/frame.png", "/pixel?x=0&y=0"] {
            let r = exchange(addr, format!("{method} {path} HTTP/1.1\r\nContent-Length: 0\r\n\r\n").as_bytes());
            assert!(r.starts_with("HTTP/1.1 405 "), "{method} {path}: {r}");
        }
    }
    assert!(get(addr, "/nothing-here").starts_with("HTTP/1.1 404 "));
    assert!(get(addr, "/").contains("<title>glint: test</title>"));
    // A stop without the page's token is refused and stops nothing.
    assert!(get(addr, "/stop").starts_with("HTTP/1.1 403 "));
    assert!(get(addr, "/stop?token=0123").starts_with("HTTP/1.1 403 "));
    assert!(!server.stop_requested());
    // Before any pass there is no frame, and the state says so.
    assert!(get(addr, "/frame.png").starts_with("HTTP/1.1 404 "));
    assert!(body(&get(addr, "/state")).contains("\"frame\":0"));
}

#[test]
fn clients_that_watch_leave_or_send_garbage_leave_the_render_unharmed() {
    let (alone, _) = render(48, &[]);
    let server = PreviewServer::start(None, "clients").unwrap();
    let addr = server.addr();
    let (watched, events) = std::thread::scope(|s| {
        // Ten pages watching until the render is done.
        let watchers: Vec<_> = (0..10)
            .map(|_| {
                s.spawn(move || {
                    let mut c = TcpStream::connect(addr).unwrap();
                    c.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
                    c.write_all(b"GET /events HTTP/1.1\r\n\r\n").unwrap();
                    let mut seen = String::new();
                    let mut buf = [0u8; 4096];
                    while !seen.contains("\"state\":\"done\"") {
                        let n = c.read(&mut buf).unwrap();
                        assert!(n > 0, "the stream ended early: {seen}");
                        seen.push_str(&String::from_utf8_lossy(&buf[..n]));
                    }
                    seen
                })
            })
            .collect();
        while server.watchers() < 10 {
            std::thread::sleep(Duration::from_millis(5));
        }
        // One that leaves mid-stream, and clients sending garbage or nothing at all.
        let mut leaver = TcpStream::connect(addr).unwrap();
        leaver.write_all(b"GET /events HTTP/1.1\r\n\r\n").unwrap();
        let mut garbage = vec![b"\x00\xff\xfe garbage \r\n\r\n".to_vec(), b"GET".to_vec(), vec![b'A'; 20000]];
        garbage.push(b"GET /pixel?x=-1&y=zz HTTP/1.1\r\n\r\n".to_vec());
        let rude: Vec<_> = garbage.into_iter().map(|g| s.spawn(move || exchange(addr, &g))).collect();
        let silent = TcpStream::connect(addr).unwrap();
        let render = s.spawn(|| render(48, &[&server]));
        std::thread::sleep(Duration::from_millis(20));
        drop(leaver);
        let (film, report) = render.join().unwrap();
        assert!(!report.cancelled);
        for r in rude {
            let r = r.join().unwrap();
            assert!(r.is_empty() || r.starts_with("HTTP/1.1 4"), "{r}");
        }
        drop(silent);
        let events: Vec<String> = watchers.into_iter().map(|w| w.join().unwrap()).collect();
        (film, events)
    });
    assert_eq!(watched.image(), alone.image(), "a watched render must give the same bits");
    assert_eq!(watched.aov(Aov::Albedo), alone.aov(Aov::Albedo));
    for e in &events {
        assert!(e.starts_with("HTTP/1.1 200 OK\r\nContent-Type: text/event-stream"), "{e}");
        assert!(e.contains("\"layers\":[{\"kind\":\"color\",\"name\":\"beauty\"}"), "{e}");
    }
    // The inspector reads the film's linear values, samples and relative error at a pixel.
    let pixel = body(&get(addr, "/pixel?x=5&y=17")).to_string();
    let v: serde_json::Value = serde_json::from_str(&pixel).unwrap();
    let p = watched.image().get(5, 17);
    let beauty: Vec<f32> =
        v["layers"]["beauty"].as_array().unwrap().iter().map(|c| c.as_f64().unwrap() as f32).collect();
    assert_eq!(beauty, [p.r, p.g, p.b]);
    assert_eq!(v["spp"], 48);
    let depth = watched.aov(Aov::Depth).unwrap().data[17 * SIZE as usize + 5];
    assert_eq!(v["layers"]["depth"][0].as_f64().unwrap() as f32, depth);
    assert!(v["rel_error"].as_f64().unwrap() >= 0.0);
    let png = get(addr, "/frame.png?layer=depth&view=false&exposure=1");
    assert!(png.starts_with("HTTP/1.1 200 OK\r\nContent-Type: image/png"), "{png}");
    assert!(get(addr, "/frame.png?layer=nope").starts_with("HTTP/1.1 404 "));
    assert!(get(addr, "/frame.png?view=sepia").starts_with("HTTP/1.1 400 "));
}

#[test]
fn the_stop_button_stops_the_render_after_a_pass() {
    let server = PreviewServer::start(None, "stop").unwrap();
    let addr = server.addr();
    let page = body(&get(addr, "/")).to_string();
    let token = page.split("const TOKEN = \"").nth(1).and_then(|t| t.split('"').next()).unwrap().to_string();
    let (film, report) = std::thread::scope(|s| {
        let render = s.spawn(|| render(1_000_000, &[&server]));
        let passes = || -> u64 {
            let state: serde_json::Value = serde_json::from_str(body(&get(addr, "/state"))).unwrap();
            state["progress"]["passes_done"].as_u64().unwrap()
        };
        while passes() < 2 {
            std::thread::sleep(Duration::from_millis(2));
        }
        assert!(get(addr, &format!("/stop?token={token}")).starts_with("HTTP/1.1 200 "));
        render.join().unwrap()
    });
    assert!(report.cancelled && report.stopped_by_viewer);
    assert!(film.passes_done() >= 2 && film.passes_done() < film.pass_count());
    assert!(body(&get(addr, "/state")).contains("\"state\":\"stopped\""));
}

/// Packets as (type, payload after the type).
type Packets = Vec<(u8, Vec<u8>)>;

/// A tev that keeps every packet it receives.
fn fake_tev() -> (SocketAddr, std::thread::JoinHandle<Packets>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let handle = std::thread::spawn(move || {
        let (mut c, _) = listener.accept().unwrap();
        let mut data = Vec::new();
        c.read_to_end(&mut data).unwrap();
        let mut packets = Vec::new();
        let mut at = 0;
        while at < data.len() {
            let len = u32::from_le_bytes(data[at..at + 4].try_into().unwrap()) as usize;
            packets.push((data[at + 4], data[at + 5..at + len].to_vec()));
            at += len;
        }
        assert_eq!(at, data.len(), "packets are whole");
        packets
    });
    (addr, handle)
}

/// Reads tev's fields in order.
struct Fields<'a>(&'a [u8]);
impl Fields<'_> {
    fn u8(&mut self) -> u8 {
        let v = self.0[0];
        self.0 = &self.0[1..];
        v
    }
    fn i32(&mut self) -> i32 {
        let v = i32::from_le_bytes(self.0[..4].try_into().unwrap());
        self.0 = &self.0[4..];
        v
    }
    fn i64(&mut self) -> i64 {
        let v = i64::from_le_bytes(self.0[..8].try_into().unwrap());
        self.0 = &self.0[8..];
        v
    }
    fn str(&mut self) -> String {
        let end = self.0.iter().position(|&b| b == 0).unwrap();
        let s = String::from_utf8(self.0[..end].to_vec()).unwrap();
        self.0 = &self.0[end + 1..];
        s
    }
    fn f32(&mut self, at: usize) -> f32 {
        f32::from_le_bytes(self.0[at * 4..at * 4 + 4].try_into().unwrap())
    }
}

#[test]
fn tev_receives_the_image_and_its_layers_channel_by_channel() {
    let (addr, tev) = fake_tev();
    let sink = TevSink::connect(&addr.to_string(), "cornell").unwrap();
    let (film, _) = render(16, &[&sink]);
    assert_eq!(sink.error(), None);
    drop(sink);
    let packets = tev.join().unwrap();
    let (kind, create) = &packets[0];
    assert_eq!(*kind, 4, "the image is created first");
    let mut f = Fields(create);
    assert_eq!(f.u8(), 1);
    assert_eq!(f.str(), "cornell");
    assert_eq!((f.i32(), f.i32()), (SIZE as i32, SIZE as i32));
    let n = f.i32() as usize;
    let names: Vec<String> = (0..n).map(|_| f.str()).collect();
    assert_eq!(names, ["R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "depth.Z"]);
    assert!(f.0.is_empty());
    // The last update of each pixel holds the film's final values, in every channel.
    let mut got = vec![f32::NAN; (SIZE * SIZE) as usize * n];
    for (kind, p) in &packets[1..] {
        assert_eq!(*kind, 6, "updates are UpdateImageV3");
        let mut f = Fields(p);
        f.u8();
        assert_eq!(f.str(), "cornell");
        assert_eq!(f.i32() as usize, n);
        let channels: Vec<String> = (0..n).map(|_| f.str()).collect();
        assert_eq!(channels, names);
        let (x, y, w, h) = (f.i32() as usize, f.i32() as usize, f.i32() as usize, f.i32() as usize);
        let offsets: Vec<i64> = (0..n).map(|_| f.i64()).collect();
        let strides: Vec<i64> = (0..n).map(|_| f.i64()).collect();
        assert_eq!(f.0.len(), w * h * n * 4);
        for py in 0..h {
            for px in 0..w {
                let i = py * w + px;
                for c in 0..n {
                    got[((y + py) * SIZE as usize + x + px) * n + c] =
                        f.f32(offsets[c] as usize + i * strides[c] as usize);
                }
            }
        }
    }
    let image = film.image();
    let (albedo, depth) = (film.aov(Aov::Albedo).unwrap(), film.aov(Aov::Depth).unwrap());
    for (i, p) in image.pixels.iter().enumerate() {
        let want = [p.r, p.g, p.b, albedo.data[3 * i], albedo.data[3 * i + 1], albedo.data[3 * i + 2], depth.data[i]];
        assert_eq!(got[i * n..(i + 1) * n], want, "pixel {i}");
    }
}
