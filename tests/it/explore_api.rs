//! `explore`'s HTTP API, through the real binary: who may call it, that its
//! final stage is `render`'s frame, what save and edit may do to the files,
//! the file watch, refused views and picks. Requests are written by hand
//! over a TcpStream so that Host and Origin are exactly what a test says.

use crate::util::{stderr, stdout, tiny_timeline, with_scene, Dir};
use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, ChildStdout, Stdio};
use std::time::Duration;

/// A running `mandelreel explore`, killed when dropped.
struct Server {
    child: Child,
    /// Kept open: the server's later writes to stdout must not fail.
    _stdout: BufReader<ChildStdout>,
    port: u16,
    token: String,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A whole HTTP response.
struct Response {
    status: u16,
    headers: Vec<(String, String)>,
    body: Vec<u8>,
}

impl Response {
    fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }

    fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("{e}: {} {}", self.status, self.text()))
    }

    fn header(&self, name: &str) -> Option<&str> {
        let found = self.headers.iter().find(|(n, _)| n == name);
        found.map(|(_, v)| v.as_str())
    }

    /// Asserts the status, showing the body if it differs.
    fn expect(self, status: u16) -> Response {
        assert_eq!(self.status, status, "body: {}", self.text());
        self
    }
}

/// Starts `explore <timeline> --port 0` in `dir` and reads the address it prints.
fn explore(dir: &Dir, timeline: &str) -> Server {
    serve(dir.command(&["explore", timeline, "--port", "0"]))
}

/// The server `command` starts, once it has printed its address.
fn serve(mut command: std::process::Command) -> Server {
    let mut child = command
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start explore");
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    out.read_line(&mut line).unwrap();
    let url = line
        .split_once(": open http://127.0.0.1:")
        .unwrap_or_else(|| panic!("no address in {line:?}"))
        .1
        .trim();
    let (port, token) = url.split_once("/?token=").expect("a token");
    Server {
        port: port.parse().expect("a port"),
        token: token.to_string(),
        child,
        _stdout: out,
    }
}

impl Server {
    fn host(&self) -> String {
        format!("127.0.0.1:{}", self.port)
    }

    /// Sends `head` (request line and headers, each ending in CRLF) and
    /// `body`, and reads the whole response.
    fn raw(&self, head: &str, body: &[u8]) -> Response {
        let mut stream = self.connect(head, body);
        let mut bytes = Vec::new();
        stream.read_to_end(&mut bytes).expect("read response");
        parse(&bytes)
    }

    fn connect(&self, head: &str, body: &[u8]) -> TcpStream {
        let mut stream = TcpStream::connect(("127.0.0.1", self.port)).expect("connect");
        // A hung server fails the test instead of hanging it.
        stream
            .set_read_timeout(Some(Duration::from_secs(120)))
            .unwrap();
        let request = format!(
            "{head}Content-Length: {}\r\nConnection: close\r\n\r\n",
            body.len()
        );
        stream.write_all(request.as_bytes()).unwrap();
        stream.write_all(body).unwrap();
        stream
    }

    /// A request as the page sends it: our Host and the token.
    fn call(&self, method: &str, path: &str, body: Option<&Value>) -> Response {
        let body = body.map_or_else(Vec::new, |b| b.to_string().into_bytes());
        let head = format!(
            "{method} {path} HTTP/1.1\r\nHost: {}\r\nx-mandelreel-token: {}\r\n\
             Content-Type: application/json\r\n",
            self.host(),
            self.token
        );
        self.raw(&head, &body)
    }

    fn get(&self, path: &str) -> Response {
        self.call("GET", path, None)
    }

    fn post(&self, path: &str, body: Value) -> Response {
        self.call("POST", path, Some(&body))
    }

    fn state(&self) -> Value {
        self.get("/api/state").expect(200).json()
    }

    /// Opens the server-sent events; returns the stream past the headers.
    fn events(&self) -> BufReader<TcpStream> {
        let head = format!(
            "GET /api/events?token={} HTTP/1.1\r\nHost: {}\r\n",
            self.token,
            self.host()
        );
        let mut reader = BufReader::new(self.connect(&head, b""));
        let mut line = String::new();
        reader.read_line(&mut line).unwrap();
        assert!(line.contains(" 200 "), "events: {line}");
        while line != "\r\n" {
            line.clear();
            reader.read_line(&mut line).unwrap();
        }
        reader
    }
}

/// The next `file` event's JSON on `events`, within 10 s.
fn next_file_event(events: &mut BufReader<TcpStream>) -> Value {
    events
        .get_ref()
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    let mut line = String::new();
    loop {
        line.clear();
        let n = events
            .read_line(&mut line)
            .expect("a file event within 10 s");
        assert!(n > 0, "the event stream ended");
        // Chunk sizes and blank lines come between the `data:` lines.
        if let Some(data) = line.trim().strip_prefix("data:") {
            let event: Value = serde_json::from_str(data.trim()).unwrap();
            if event["kind"] == "file" {
                return event;
            }
        }
    }
}

fn parse(bytes: &[u8]) -> Response {
    let end = bytes
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .unwrap_or_else(|| panic!("no header end in {:?}", String::from_utf8_lossy(bytes)));
    let head = String::from_utf8_lossy(&bytes[..end]).into_owned();
    let mut lines = head.split("\r\n");
    let status = lines.next().unwrap().split(' ').nth(1).unwrap();
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(n, v)| (n.trim().to_ascii_lowercase(), v.trim().to_string()))
        .collect();
    let mut body = bytes[end + 4..].to_vec();
    if headers.contains(&("transfer-encoding".into(), "chunked".into())) {
        body = unchunk(&body);
    }
    Response {
        status: status.parse().unwrap(),
        headers,
        body,
    }
}

fn unchunk(mut rest: &[u8]) -> Vec<u8> {
    let mut body = Vec::new();
    loop {
        let line = rest.windows(2).position(|w| w == b"\r\n").unwrap();
        let size = std::str::from_utf8(&rest[..line]).unwrap();
        let size = usize::from_str_radix(size.split(';').next().unwrap().trim(), 16).unwrap();
        if size == 0 {
            return body;
        }
        body.extend_from_slice(&rest[line + 2..line + 2 + size]);
        rest = &rest[line + 2 + size + 2..];
    }
}

/// A PNG's size and pixel bytes.
fn pixels(png: &[u8]) -> (u32, u32, Vec<u8>) {
    let image = image::load_from_memory(png).expect("a PNG");
    (image.width(), image.height(), image.as_bytes().to_vec())
}

fn zoom_ron() -> String {
    std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/timelines/zoom.ron")).unwrap()
}

#[test]
fn only_our_page_with_its_token_is_answered() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 9.0));
    let s = explore(&d, "t.ron");
    let (host, token) = (s.host(), s.token.clone());
    let get = |headers: &str| s.raw(&format!("GET /api/state HTTP/1.1\r\n{headers}"), b"");

    get(&format!("Host: {host}\r\n")).expect(403);
    get(&format!(
        "Host: {host}\r\nx-mandelreel-token: {}\r\n",
        "0".repeat(32)
    ))
    .expect(403);
    // DNS rebinding: a name that resolves here, with the right token.
    let evil = format!(
        "Host: evil.example:{}\r\nx-mandelreel-token: {token}\r\n",
        s.port
    );
    let refused = get(&evil).expect(403);
    assert!(refused.text().contains("Host"), "{}", refused.text());
    let ours = format!("Host: {host}\r\nx-mandelreel-token: {token}\r\n");
    get(&format!("{ours}Origin: http://evil.example\r\n")).expect(403);
    get(&format!("{ours}Origin: http://{host}\r\n")).expect(200);
    assert_eq!(get(&ours).expect(200).json()["name"], "t.ron");
    assert!(get(&format!(
        "Host: localhost:{}\r\nx-mandelreel-token: {token}\r\n",
        s.port
    ))
    .expect(200)
    .header("cache-control")
    .is_some_and(|c| c == "no-store"));
    // The page itself, with the token in the query as its address gives it.
    let page = format!("GET /?token={token} HTTP/1.1\r\nHost: {host}\r\n");
    s.raw(&page, b"").expect(200);
    s.raw(
        &format!("GET /?token=x{token} HTTP/1.1\r\nHost: {host}\r\n"),
        b"",
    )
    .expect(403);
    // Its script, style and events take it there too; no other route does.
    for path in ["/explore.js", "/explore.css"] {
        let asset = format!("GET {path}?token={token} HTTP/1.1\r\nHost: {host}\r\n");
        s.raw(&asset, b"").expect(200);
    }
    for (method, path) in [
        ("GET", "/api/state"),
        ("POST", "/api/save"),
        ("POST", "/api/edit"),
    ] {
        let head = format!(
            "{method} {path}?token={token} HTTP/1.1\r\nHost: {host}\r\nContent-Type: application/json\r\n"
        );
        let refused = s.raw(&head, b"{}").expect(403);
        assert!(
            refused.text().contains("token"),
            "{path}: {}",
            refused.text()
        );
    }

    // Listening on loopback only: the machine's own outward address is refused.
    match outward_address() {
        None => eprintln!("no non-loopback address here: skipping the bind check"),
        Some(ip) => {
            let to = std::net::SocketAddr::new(ip, s.port);
            let connected = TcpStream::connect_timeout(&to, Duration::from_secs(2));
            assert!(connected.is_err(), "explore answered on {to}");
        }
    }
}

/// This machine's address on its default route, if it has one (a UDP
/// "connect" sends nothing; it only picks the route).
fn outward_address() -> Option<std::net::IpAddr> {
    let socket = std::net::UdpSocket::bind("0.0.0.0:0").ok()?;
    socket.connect("192.0.2.1:9").ok()?;
    let ip = socket.local_addr().ok()?.ip();
    (!ip.is_loopback() && !ip.is_unspecified()).then_some(ip)
}

#[test]
fn the_final_stage_is_renders_frame() {
    let d = Dir::new();
    d.write(
        "t.ron",
        &with_scene(&tiny_timeline(3, 9.0), "samples_per_pixel: 4"),
    );
    let s = explore(&d, "t.ron");
    // The timeline's own size and samples, and a view that changes both.
    let cases = [
        (json!({"frame": 0}), vec![], "48x27", "4"),
        (json!({"frame": 2}), vec![], "48x27", "4"),
        (
            json!({"frame": 2, "size": "32x18", "samples": 2}),
            vec!["--size", "32x18", "--samples", "2"],
            "32x18",
            "2",
        ),
    ];
    for (i, (view, args, size, samples)) in cases.into_iter().enumerate() {
        let frame = view["frame"].to_string();
        let shown = s
            .post("/api/render", json!({"view": view, "stage": "final"}))
            .expect(200);
        let out = format!("o{i}");
        let mut render = vec!["render", "t.ron", "--frames", &frame, "--out", &out, "-q"];
        render.extend(args);
        d.ok(&render);
        let written = d.bytes(&format!("{out}/frame_{frame:0>5}.png"));
        assert!(
            pixels(&shown.body) == pixels(&written),
            "{view}: the final stage's pixels differ from render's"
        );
        // The whole file, its hash and statistics as well.
        assert!(
            shown.body == written,
            "{view}: the PNG differs from render's"
        );
        assert_eq!(shown.header("content-type"), Some("image/png"));
        assert_eq!(shown.header("x-size"), Some(size));
        assert_eq!(shown.header("x-samples"), Some(samples));
    }
}

#[test]
fn save_writes_only_its_file_and_new_plain_names() {
    let d = Dir::new();
    // The timeline in a folder of its own, so that `../x.ron` would land in
    // a folder this test lists; `a/` exists so `a/b.ron` could be written.
    std::fs::create_dir_all(d.path().join("work/a")).unwrap();
    let original = tiny_timeline(2, 9.0);
    d.write("work/t.ron", &original);
    d.write("work/other.ron", "// someone else's\n");
    let s = explore(&d, "work/t.ron");
    let listing = || (d.files(""), d.files("work"), d.files("work/a"));
    let before = listing();
    let bad = [
        "../x.ron",
        "a/b.ron",
        ".hidden.ron",
        "x.txt",
        "other.ron",
        "t.ron",
        // Shows as "ron.png"; a name that is only a space; spaces at an end.
        "\u{202E}gnp.ron",
        " .ron",
        " x.ron",
        "x .ron",
        "x\u{200B}.ron",
        "film\u{E0041}.ron",
        // A joiner outside a word hides.
        "\u{200C}x.ron",
        "x\u{200D}.ron",
        "x\u{200D}\u{200D}y.ron",
        // Between Latin letters it only hides: it shows as "report.ron".
        "rep\u{200D}ort.ron",
        ".ron",
    ];
    for name in bad {
        let refused = s.post("/api/save", json!({ "name": name }));
        assert!(
            (400..500).contains(&refused.status),
            "{name}: {} {}",
            refused.status,
            refused.text()
        );
        assert_eq!(listing(), before, "{name} wrote a file");
    }
    assert_eq!(d.bytes("work/other.ron"), b"// someone else's\n");
    assert_eq!(d.bytes("work/t.ron"), original.as_bytes());

    // A plain save after an edit writes the timeline it opened.
    let edit = json!({"edits": [{"kind": "set_key", "track": "fractal.power", "time": 0.5, "value": [10]}]});
    assert_eq!(s.post("/api/edit", edit).expect(200).json()["dirty"], true);
    let saved = s.post("/api/save", json!({})).expect(200).json();
    assert_eq!(saved["dirty"], false);
    let text = saved["text"].as_str().unwrap();
    assert_ne!(text, original);
    assert_eq!(d.bytes("work/t.ron"), text.as_bytes());

    // A new plain name: a new file beside it, with the same text.
    let copy = s.post("/api/save", json!({"name": "copy.ron"})).expect(200);
    assert_eq!(d.bytes("work/copy.ron"), text.as_bytes());
    assert!(copy.json()["path"].as_str().unwrap().ends_with("copy.ron"));
    assert_eq!(d.files("work"), ["a", "copy.ron", "other.ron", "t.ron"]);
    // Persian spells "the films" (فیلم‌ها) with a non-joiner between letters.
    let persian = "\u{0641}\u{06CC}\u{0644}\u{0645}\u{200C}\u{0647}\u{0627}.ron";
    s.post("/api/save", json!({ "name": persian })).expect(200);
    assert_eq!(d.bytes(&format!("work/{persian}")), text.as_bytes());
    // Hindi's half-form ksha (क्‍ष) takes a joiner after the virama.
    let hindi = "\u{0915}\u{094D}\u{200D}\u{0937}.ron";
    s.post("/api/save", json!({ "name": hindi })).expect(200);
    assert_eq!(d.bytes(&format!("work/{hindi}")), text.as_bytes());
}

#[test]
fn edits_keep_comments_and_bad_ones_change_nothing() {
    let d = Dir::new();
    let original = zoom_ron();
    d.write("zoom.ron", &original);
    let s = explore(&d, "zoom.ron");

    // Invalid values are placed where they are written, as `render` places them.
    let fov = 1 + original
        .lines()
        .position(|l| l.contains("fov_degrees"))
        .unwrap();
    let fov = format!("zoom.ron:{fov}:");
    let refusals = [
        (
            json!({"kind": "set_scene", "parameter": "camera.fov_degrees", "value": [0]}),
            "fov_degrees",
            Some(&fov),
        ),
        (
            json!({"kind": "set_scene", "parameter": "camera.fov_degrees", "value": [500]}),
            "fov_degrees",
            Some(&fov),
        ),
        (
            json!({"kind": "set_key", "track": "camera.nope", "time": 1, "value": [1]}),
            "camera.nope",
            None,
        ),
        (
            json!({"kind": "set_key", "track": "camera.position", "time": 1, "value": [1, 2]}),
            "camera.position",
            None,
        ),
    ];
    for (edit, names, at) in refusals {
        let refused = s.post("/api/edit", json!({ "edits": [edit] })).expect(422);
        let message = refused.text();
        assert!(message.contains(names), "{edit}: {message}");
        assert!(
            at.is_none_or(|at| message.starts_with(at.as_str())),
            "{edit}: {message}"
        );
        let state = s.state();
        assert_eq!(state["text"], original.as_str(), "{edit} changed the text");
        assert_eq!(state["dirty"], false);
    }

    let key = json!({"kind": "set_key", "track": "camera.distance", "time": 2.5, "value": [0.5]});
    let edited = s
        .post("/api/edit", json!({"edits": [key]}))
        .expect(200)
        .json();
    let keys = &edited["tracks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["name"] == "camera.distance")
        .unwrap()["keys"];
    assert_eq!(keys.as_array().unwrap().len(), 3, "{keys}");
    s.post("/api/save", json!({})).expect(200);
    let saved = String::from_utf8(d.bytes("zoom.ron")).unwrap();
    assert!(saved.contains("2.5"), "{saved}");
    for comment in original
        .lines()
        .filter_map(|l| l.find("//").map(|i| &l[i..]))
    {
        assert!(saved.contains(comment), "lost {comment:?}:\n{saved}");
    }
    let info = d.run(&["info", "zoom.ron"]);
    assert!(info.status.success(), "{}", crate::util::stderr(&info));
    assert!(!stdout(&info).is_empty());
}

/// Writes `name` whole at once, as editors save (a plain write could be
/// read half-written, which the server rightly reports as an error).
fn replace(d: &Dir, name: &str, text: &str) {
    d.write(".next", text);
    std::fs::rename(d.path().join(".next"), d.path().join(name)).unwrap();
}

#[test]
fn disk_changes_are_taken_in_unless_edited_here() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 9.0));
    let s = explore(&d, "t.ron");
    let mut events = s.events();

    replace(&d, "t.ron", &tiny_timeline(2, 11.0));
    let event = next_file_event(&mut events);
    assert_eq!(
        event,
        json!({"kind": "file", "dirty": false, "error": null})
    );
    let state = s.state();
    assert!(
        state["text"].as_str().unwrap().contains("value: 11"),
        "{state}"
    );
    assert_eq!(state["dirty"], false);

    // An edit not saved: the file's change is reported, not taken in.
    let edit = json!({"edits": [{"kind": "set_key", "track": "fractal.power", "time": 0.5, "value": [10]}]});
    let edited = s.post("/api/edit", edit).expect(200).json()["text"].clone();
    replace(&d, "t.ron", &tiny_timeline(2, 12.0));
    let event = next_file_event(&mut events);
    assert_eq!(event["dirty"], true, "{event}");
    let state = s.state();
    assert_eq!(state["text"], edited);
    assert!(!state["text"].as_str().unwrap().contains("value: 12"));
    assert_eq!(state["dirty"], true);

    // Reload drops the edit for the file's text.
    let reloaded = s.post("/api/reload", json!({})).expect(200).json();
    assert_eq!(reloaded["text"], tiny_timeline(2, 12.0).as_str());
    assert_eq!(reloaded["dirty"], false);
}

#[test]
fn bad_views_are_refused_with_the_reason() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(3, 9.0));
    let s = explore(&d, "t.ron");
    let views = [
        (json!({"frame": 3}), "past the last frame"),
        (json!({"frame": 0, "size": "0x5"}), "0x5"),
        (json!({"frame": 0, "size": "99999x99999"}), "99999x99999"),
        (json!({"frame": 0, "size": "3841x2160"}), "3840x2160"),
        (
            json!({"frame": 0, "overrides": {"camera.nope": [1]}}),
            "camera.nope",
        ),
        (
            json!({"frame": 0, "overrides": {"camera.position": [1, 2]}}),
            "camera.position",
        ),
        (
            json!({"frame": 0, "overrides": {"camera.fov_degrees": [0]}}),
            "fov_degrees",
        ),
        (json!({"frame": 0, "samples": 0}), "samples"),
    ];
    for (view, reason) in views {
        for stage in ["quick", "final"] {
            let refused = s.post("/api/render", json!({"view": view, "stage": stage}));
            let message = refused.expect(422).text();
            assert!(message.contains(reason), "{view}: {message}");
        }
        let picked = s.post("/api/pick", json!({"view": view, "x": 0, "y": 0}));
        assert!(picked.expect(422).text().contains(reason));
        let estimated = s.post("/api/estimate", view.clone());
        assert!(estimated.expect(422).text().contains(reason));
    }
    let outside = s.post("/api/pick", json!({"view": {"frame": 0}, "x": 48, "y": 0}));
    assert!(outside.expect(422).text().contains("outside 48x27"));
    s.get("/api/values?frame=3").expect(422);
    // Still answering, and still renders a good view.
    assert_eq!(s.state()["frames"], 3);
    let quick = s.post(
        "/api/render",
        json!({"view": {"frame": 2}, "stage": "quick"}),
    );
    assert_eq!(quick.expect(200).header("x-size"), Some("48x27"));
}

#[test]
fn the_explorer_shows_the_quaternion_as_render_writes_it() {
    let d = Dir::new();
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/timelines/quaternion.ron"
    ))
    .unwrap();
    d.write("q.ron", &text);
    let s = explore(&d, "q.ron");
    let view = json!({"frame": 30, "size": "48x27", "samples": 1});
    let shown = s
        .post("/api/render", json!({"view": view, "stage": "final"}))
        .expect(200);
    d.ok(&[
        "render",
        "q.ron",
        "--frames",
        "30",
        "--size",
        "48x27",
        "--samples",
        "1",
        "--out",
        "o",
        "-q",
    ]);
    assert!(pixels(&shown.body) == pixels(&d.bytes("o/frame_00030.png")));
    let pick = json!({"view": view, "x": 24, "y": 13});
    let report = s.post("/api/pick", pick).expect(200).json();
    assert_eq!(report["hit"], true, "{report}");
    assert_eq!(report["fractal"]["formula"], "Quaternion", "{report}");
}

#[test]
fn a_pick_at_the_centre_of_the_zoom_finds_its_target() {
    let d = Dir::new();
    d.write("zoom.ron", &zoom_ron());
    let s = explore(&d, "zoom.ron");
    let pick = json!({"view": {"frame": 119, "size": "64x36"}, "x": 32, "y": 18});
    let report = s.post("/api/pick", pick).expect(200).json();
    assert_eq!(report["hit"], true, "{report}");
    let target = [0.503044367725, 0.443308880733, 0.397566446799];
    for (axis, want) in target.iter().enumerate() {
        let got = report["point"][axis].as_f64().unwrap();
        assert!(
            (got - want).abs() < 1e-3,
            "axis {axis}: {got} vs {want}: {report}"
        );
    }
}

#[test]
fn save_does_not_silently_write_over_a_file_changed_on_disk() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 9.0));
    let s = explore(&d, "t.ron");
    let mut events = s.events();
    // The editor's text is not valid yet: the page keeps the last valid one.
    replace(&d, "t.ron", "(fps: 0, size: (8, 6))");
    assert!(next_file_event(&mut events)["error"].is_string());
    let edit = json!({"edits": [{"kind": "set_key", "track": "fractal.power", "time": 0.5, "value": [10]}]});
    s.post("/api/edit", edit).expect(200);
    let refused = s.post("/api/save", json!({})).expect(409);
    assert!(
        refused.text().contains("changed on disk"),
        "{}",
        refused.text()
    );
    assert_eq!(d.bytes("t.ron"), b"(fps: 0, size: (8, 6))");
    s.post("/api/save", json!({"overwrite": true})).expect(200);
    assert!(String::from_utf8(d.bytes("t.ron"))
        .unwrap()
        .contains("value: 10"));
}

#[cfg(unix)]
#[test]
fn save_writes_through_a_link_and_keeps_the_files_mode() {
    let d = Dir::new();
    let real = d.linked_private_timeline(&tiny_timeline(2, 9.0));
    let s = explore(&d, "link.ron");
    let edit = json!({"edits": [{"kind": "set_key", "track": "fractal.power", "time": 0.5, "value": [10]}]});
    s.post("/api/edit", edit).expect(200);
    s.post("/api/save", json!({})).expect(200);
    d.assert_written_through_the_link(&real, "value: 10");
}

#[test]
fn many_edits_at_once_are_refused_and_the_text_kept() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 9.0));
    let s = explore(&d, "t.ron");
    let before = s.state()["text"].clone();
    let edits: Vec<Value> = (0..65)
        .map(|i| json!({"kind": "set_key", "track": "fractal.power", "time": 0.01 * i as f64 + 0.1, "value": [9]}))
        .collect();
    let refused = s.post("/api/edit", json!({ "edits": edits })).expect(422);
    assert!(refused.text().contains("at most 64"), "{}", refused.text());
    assert_eq!(s.state()["text"], before);
}

#[cfg(unix)]
#[test]
fn an_interrupt_stops_the_server_while_a_page_listens() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 9.0));
    let mut s = explore(&d, "t.ron");
    let _events = s.events();
    let pid = nix::unistd::Pid::from_raw(s.child.id() as i32);
    nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGINT).unwrap();
    let started = std::time::Instant::now();
    while s.child.try_wait().unwrap().is_none() {
        assert!(
            started.elapsed() < Duration::from_secs(4),
            "still serving after Ctrl-C"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_change_on_disk_just_before_save_is_not_written_over() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 9.0));
    let s = explore(&d, "t.ron");
    let edit = json!({"edits": [{"kind": "set_key", "track": "fractal.power", "time": 0.5, "value": [10]}]});
    s.post("/api/edit", edit).expect(200);
    // Saved by an editor a moment ago: the watch has not looked twice yet.
    let theirs = format!("{}// theirs\n", tiny_timeline(2, 9.0));
    d.write("t.ron", &theirs);
    s.post("/api/save", json!({})).expect(409);
    assert_eq!(d.bytes("t.ron"), theirs.as_bytes());
}

#[test]
fn edits_sent_together_take_turns() {
    let d = Dir::new();
    // Long enough that one edit is still being checked when the next comes.
    let keys: String = (0..4000)
        .map(|i| format!("(time: {}, value: 8),\n", i as f64 * 0.001))
        .collect();
    let text = format!(
        "(fps: 24, frames: 2, size: (48, 27), tracks: {{\"fractal.power\": (keys: [\n{keys}])}})"
    );
    d.write("t.ron", &text);
    let s = explore(&d, "t.ron");
    let statuses: Vec<u16> = std::thread::scope(|scope| {
        let sent: Vec<_> = [5.5, 6.5]
            .map(|time| {
                let s = &s;
                scope.spawn(move || {
                    let edit = json!({"edits": [{"kind": "set_key", "track": "fractal.power", "time": time, "value": [9]}]});
                    s.post("/api/edit", edit).status
                })
            })
            .into_iter()
            .collect();
        sent.into_iter().map(|t| t.join().unwrap()).collect()
    });
    assert_eq!(statuses, [200, 200]);
    let state = s.state()["text"].as_str().unwrap().to_string();
    assert!(state.contains("time: 5.5") && state.contains("time: 6.5"));
}

#[test]
fn auto_iterations_are_shown_per_frame_and_never_written_over() {
    use crate::auto::{counts, ZOOM};
    let d = Dir::new();
    d.write("zoom.ron", ZOOM);
    let s = explore(&d, "zoom.ron");
    // The counts shown are those `info` lists, frame by frame.
    let info = stdout(&d.ok(&["info", "zoom.ron"]));
    for (frame, count) in counts(&info).into_iter().enumerate() {
        let shown = s.get(&format!("/api/iterations?frame={frame}")).expect(200);
        let shown = shown.json();
        assert_eq!(shown["count"], count, "frame {frame}: {shown}");
        assert_eq!(shown["margin"], 1);
        assert_eq!(shown["shown"], format!("Auto → {count} (target)"));
    }
    s.get("/api/iterations?frame=3").expect(422);

    // A number over `Auto`, as a scene value, a key or a view's value, is
    // refused with the way to fix the count, and the text stays as it was.
    let refusals = [
        json!({"kind": "set_scene", "parameter": "fractal.iterations", "value": [20]}),
        json!({"kind": "set_key", "track": "fractal.iterations", "time": 0, "value": [20]}),
    ];
    for edit in refusals {
        let refused = s.post("/api/edit", json!({ "edits": [edit] })).expect(422);
        assert!(
            refused.text().contains("writes no number over it"),
            "{edit}: {}",
            refused.text()
        );
        assert_eq!(s.state()["text"], ZOOM, "{edit} changed the text");
    }
    let view = json!({"frame": 0, "overrides": {"fractal.iterations": [20]}});
    let refused = s.post("/api/render", json!({"view": view, "stage": "quick"}));
    assert!(refused.expect(422).text().contains("says `Auto`"));

    // A count the timeline gives is shown as it is.
    d.write("fixed.ron", &ZOOM.replace("Auto(margin: 1)", "9"));
    let fixed = explore(&d, "fixed.ron");
    let shown = fixed.get("/api/iterations?frame=2").expect(200).json();
    assert_eq!(
        shown,
        json!({"margin": null, "count": 9, "decided": null, "shown": "9"})
    );
}

/// A fisheye's angle and stereo's separation are parameters the explorer
/// lists, shows at a frame and sets in a view; a scene without them
/// shows none and refuses a value for them.
#[test]
fn the_fisheyes_angle_and_the_eyes_separation_are_listed_and_set() {
    let d = Dir::new();
    let dome = tiny_timeline(1, 8.0).replace(
        "camera: (",
        "camera: (projection: Fisheye(degrees: 180), stereo: (eye_separation: 0.03, layout: SideBySide), ",
    );
    d.write("t.ron", &dome);
    d.write("plain.ron", &tiny_timeline(1, 8.0));
    let s = explore(&d, "t.ron");
    let listed = s.state()["parameters"].to_string();
    for name in ["camera.projection.degrees", "camera.stereo.eye_separation"] {
        assert!(listed.contains(&format!("[\"{name}\",1]")), "{listed}");
    }
    let values = s.get("/api/values?frame=0").expect(200).json();
    assert_eq!(values["camera.projection.degrees"], json!([180.0]));
    assert_eq!(values["camera.stereo.eye_separation"], json!([0.03]));
    let view = |degrees: f64| {
        let view = json!({"frame": 0, "overrides": {"camera.projection.degrees": [degrees]}});
        let shown = s.post("/api/render", json!({"view": view, "stage": "final"}));
        pixels(&shown.expect(200).body)
    };
    assert!(view(180.0) != view(120.0), "the angle set changes nothing");
    let bad = json!({"frame": 0, "overrides": {"camera.projection.degrees": [400]}});
    let refused = s.post("/api/render", json!({"view": bad, "stage": "quick"}));
    assert!(refused
        .expect(422)
        .text()
        .contains("camera.projection.degrees"));
    drop(s);
    let plain = explore(&d, "plain.ron");
    let values = plain.get("/api/values?frame=0").expect(200).json();
    assert_eq!(values["camera.projection.degrees"], Value::Null);
    let view = json!({"frame": 0, "overrides": {"camera.stereo.eye_separation": [0.1]}});
    let refused = plain.post("/api/render", json!({"view": view, "stage": "quick"}));
    let message = refused.expect(422).text();
    assert!(
        message.contains("camera.stereo.eye_separation") && message.contains("stereo"),
        "{message}"
    );
}

/// The page holds numbers: a deep target's nearest numbers sent back
/// unmoved, to view or to key the camera, keep the digits they round.
#[test]
fn a_deep_targets_digits_survive_viewing_and_keying() {
    let d = Dir::new();
    let tip = "-1.10408951367381233764950538762334472132";
    let at = |x: &str| format!("(\"{x}\", \"{tip}\", \"0\")");
    let text = format!(
        "(fps: 4, frames: 5, size: (32, 18), scene: (camera: (position: (1.5, -2.4, 1.2), target: {}, fov_degrees: 40), fractal: (iterations: 40)), tracks: {{ \"camera.distance\": (keys: [(time: 0, value: 1e-30)]), \"camera.target\": (interpolation: Linear, keys: [(time: 0, value: {}), (time: 1, value: {})]) }})",
        at("0"),
        at("0"),
        at("0.000000000000000000000000000002")
    );
    d.write("deep.ron", &text);
    let s = explore(&d, "deep.ron");
    let values = s.get("/api/values?frame=2").expect(200).json();
    let distance = values["camera.distance"][0].as_f64().unwrap();
    assert!((distance / 1e-30 - 1.0).abs() < 1e-12, "{values}");
    let target = values["camera.target"].clone();
    let view = |overrides: Value| {
        let view = json!({"frame": 2, "overrides": overrides});
        let shown = s.post("/api/render", json!({"view": view, "stage": "final"}));
        pixels(&shown.expect(200).body)
    };
    assert!(view(json!({})) == view(json!({ "camera.target": target })));
    let key = |value: &Value| json!({"edits": [{"kind": "set_key", "track": "camera.target", "time": 0.5, "value": value}]});
    s.post("/api/edit", key(&target)).expect(200);
    let edited = s.state()["text"].as_str().unwrap().to_string();
    let midway = at("0.000000000000000000000000000001");
    assert!(edited.contains(&format!("value: {midway}")), "{edited}");
    // A value the page moved is written as it is.
    s.post("/api/edit", key(&json!([0.25, -1.1, 0.0])))
        .expect(200);
    let edited = s.state()["text"].as_str().unwrap().to_string();
    assert!(edited.contains("value: (0.25, -1.1, 0)"), "{edited}");
}

/// Digits go both ways: the page is told a point's strings of digits,
/// and strings it sends are viewed and written as they are; a parameter
/// that takes numbers refuses them.
#[test]
fn a_point_is_shown_viewed_and_keyed_in_its_digits() {
    let d = Dir::new();
    let tip = "-1.10408951367381233764950538762334472132";
    let text = format!(
        "(fps: 4, frames: 2, size: (32, 18), scene: (camera: (position: (1.5, -2.4, 1.2), target: (\"0\", \"{tip}\", \"0\"), fov_degrees: 40), fractal: (iterations: 40)), tracks: {{ \"camera.distance\": (keys: [(time: 0, value: 1e-30)]) }})"
    );
    d.write("deep.ron", &text);
    let s = explore(&d, "deep.ron");
    let digits = s.get("/api/digits?frame=1").expect(200).json();
    assert_eq!(digits["camera.target"], json!(["0", tip, "0"]), "{digits}");
    // The zoom holds the camera 1e-30 from the target, towards (1.5, -2.4, 1.2).
    let position = &digits["camera.position"];
    let component = |i: usize| position[i].as_str().unwrap().parse::<f64>().unwrap();
    let towards = [1.5, -2.4 - tip.parse::<f64>().unwrap(), 1.2];
    let length = towards.iter().map(|v| v * v).sum::<f64>().sqrt();
    for i in [0, 2] {
        let expected = 1e-30 * towards[i] / length;
        assert!((component(i) / expected - 1.0).abs() < 1e-9, "{digits}");
    }
    let y = position[1].as_str().unwrap();
    assert!(y.starts_with(&tip[..30]) && y != tip, "{digits}");
    s.get("/api/digits?frame=2").expect(422);
    // 2e-30 along x: a pixel's width at this depth, which f64 rounds away.
    let moved = json!(["0.000000000000000000000000000002", tip, "0"]);
    let view = |overrides: Value| {
        let view = json!({"frame": 1, "overrides": overrides});
        let shown = s.post("/api/render", json!({"view": view, "stage": "final"}));
        pixels(&shown.expect(200).body)
    };
    assert!(view(json!({})) != view(json!({ "camera.target": moved })));
    let key = |track: &str, value: &Value| json!({"edits": [{"kind": "set_key", "track": track, "time": 0.25, "value": value}]});
    s.post("/api/edit", key("camera.target", &moved))
        .expect(200);
    let edited = s.state()["text"].as_str().unwrap().to_string();
    let written = format!("(\"0.000000000000000000000000000002\", \"{tip}\", \"0\")");
    assert!(edited.contains(&format!("value: {written}")), "{edited}");
    let refused = s.post("/api/edit", key("camera.up", &json!(["0.1", 1, 0])));
    let message = refused.expect(422).text();
    assert!(message.contains("camera.up: takes numbers"), "{message}");
}

/// Beyond loopback only when asked for, saying where and that it is plain
/// HTTP.
#[test]
fn serving_the_network_needs_a_flag_and_names_its_addresses() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 9.0));
    let refused = d.run(&["explore", "t.ron", "--bind", "0.0.0.0", "--port", "0"]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(
        stderr(&refused).contains("add --network"),
        "{}",
        stderr(&refused)
    );
    let lines = announced(&d, "0.0.0.0");
    assert!(lines[0].contains(": open http://127.0.0.1:"), "{lines:?}");
    assert!(
        lines[2].starts_with("Other machines reach it at "),
        "{lines:?}"
    );
    if let Some(ip) = outward_address() {
        assert!(
            lines[2].contains(&format!("http://{ip}:")),
            "{ip}: {lines:?}"
        );
    }
    assert!(lines[3].contains("plain HTTP"), "{lines:?}");
    // `::` opens at IPv6's loopback, and where it also answers IPv4 (Linux's
    // default) it names the IPv4 addresses too.
    if std::net::TcpListener::bind("[::]:0").is_err() {
        return;
    }
    let lines = announced(&d, "::");
    assert!(lines[0].contains(": open http://[::1]:"), "{lines:?}");
    let dual =
        std::fs::read_to_string("/proc/sys/net/ipv6/bindv6only").is_ok_and(|v| v.trim() == "0");
    if let (true, Some(ip)) = (dual, outward_address()) {
        assert!(
            lines[2].contains(&format!("http://{ip}:")),
            "{ip}: {lines:?}"
        );
    }
}

/// The first four lines `explore` prints, serving `t.ron` in `d` at `bind`.
fn announced(d: &Dir, bind: &str) -> Vec<String> {
    let mut child = d
        .command(&[
            "explore",
            "t.ron",
            "--bind",
            bind,
            "--network",
            "--port",
            "0",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("start explore");
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let lines: Vec<String> = (0..4)
        .map(|_| {
            let mut line = String::new();
            out.read_line(&mut line).unwrap();
            line
        })
        .collect();
    child.kill().unwrap();
    child.wait().unwrap();
    lines
}

/// Values the page shows are the file's, not their f32 roundings, and a
/// value typed is written with nothing else rewritten.
#[test]
fn values_are_the_numbers_the_file_writes() {
    let d = Dir::new();
    let text = with_scene(
        &tiny_timeline(1, 8.0),
        "quality: (fudge: 0.30000001192092896), look: (base_colour: (0.55, 0.50, 0.45), light_colour: (1.05, 1.0, 0.9)), effects: (fog: (density: 0.3, colour: (0.09, 0.1, 0.12)))",
    );
    d.write("t.ron", &text);
    let s = explore(&d, "t.ron");
    let values = s.get("/api/values?frame=0").expect(200).json();
    assert_eq!(
        values["look.base_colour"],
        json!([0.55, 0.5, 0.45]),
        "{values}"
    );
    assert_eq!(values["look.light_colour"], json!([1.05, 1.0, 0.9]));
    assert_eq!(values["effects.fog.colour"], json!([0.09, 0.1, 0.12]));
    assert_eq!(values["effects.fog.density"], json!([0.3]));
    // An f64 field keeps every digit, though f32 holds this value exactly.
    assert_eq!(values["quality.fudge"], json!([0.30000001192092896]));
    // Typing 0.9 into the first component, as the page sends it, and
    // saving changes those bytes alone.
    let typed = json!([
        0.9,
        values["look.base_colour"][1],
        values["look.base_colour"][2]
    ]);
    let edit =
        json!({"edits": [{"kind": "set_scene", "parameter": "look.base_colour", "value": typed}]});
    s.post("/api/edit", edit).expect(200);
    s.post("/api/save", json!({})).expect(200);
    let saved = String::from_utf8(d.bytes("t.ron")).unwrap();
    assert_eq!(
        saved,
        text.replace("(0.55, 0.50, 0.45)", "(0.9, 0.50, 0.45)")
    );
}

/// Clients that never finish their headers are dropped in time: with the
/// server allowed 256 open files, 300 of them held open, and a real
/// request made after them is still answered.
#[test]
fn slow_clients_cannot_starve_the_page() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 9.0));
    let mut command = std::process::Command::new("sh");
    command
        .args(["-c", "ulimit -n 256 && exec \"$0\" explore t.ron --port 0"])
        .arg(env!("CARGO_BIN_EXE_mandelreel"))
        .current_dir(d.path());
    let s = serve(command);
    let slow: Vec<TcpStream> = (0..300)
        .filter_map(|_| {
            let mut stream = TcpStream::connect(("127.0.0.1", s.port)).ok()?;
            stream
                .write_all(b"GET /api/state HTTP/1.1\r\nHost: 127.0.0.1\r\n")
                .ok()?;
            Some(stream)
        })
        .collect();
    assert!(slow.len() >= 250, "{} slow clients connected", slow.len());
    let started = std::time::Instant::now();
    let answered = s.get("/api/state").expect(200).json();
    assert_eq!(answered["name"], "t.ron");
    // Three rounds of the 5 s header timeout at most, well inside the
    // request's own 120 s.
    assert!(
        started.elapsed() < Duration::from_secs(60),
        "{:?}",
        started.elapsed()
    );
    drop(slow);
}

/// A request without the token is answered and its connection closed, so
/// no client without it holds a connection by asking again and again.
#[test]
fn a_refused_request_ends_its_connection() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 9.0));
    let s = explore(&d, "t.ron");
    let mut stream = TcpStream::connect(("127.0.0.1", s.port)).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(20)))
        .unwrap();
    let ask = b"GET /api/state HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
    stream.write_all(ask).unwrap();
    // Read to the end: the server closes the connection after its answer
    // (a kept-alive one would time out the read instead).
    let mut answer = String::new();
    stream
        .read_to_string(&mut answer)
        .expect("the server closes the connection");
    assert!(answer.starts_with("HTTP/1.1 403"), "{answer}");
    assert!(
        answer.to_lowercase().contains("connection: close"),
        "{answer}"
    );
}

/// Playback frames take turns: however many are asked for at once, at
/// most two render together, and each is answered.
#[test]
fn playback_frames_render_two_at_a_time() {
    let d = Dir::new();
    d.write("t.ron", &tiny_timeline(2, 9.0));
    let s = explore(&d, "t.ron");
    let view = json!({"frame": 1, "size": "480x270"});
    let playing: Vec<usize> = std::thread::scope(|scope| {
        let asks: Vec<_> = (0..12)
            .map(|_| {
                scope.spawn(|| {
                    let shown = s.post("/api/render", json!({"view": view, "stage": "play"}));
                    let shown = shown.expect(200);
                    shown.header("x-playing").unwrap().parse::<usize>().unwrap()
                })
            })
            .collect();
        asks.into_iter().map(|a| a.join().unwrap()).collect()
    });
    assert!(playing.iter().all(|&n| (1..=2).contains(&n)), "{playing:?}");
}
