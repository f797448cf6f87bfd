//! The explorer in a real browser: headless Chromium, driven through
//! chromedriver (WebDriver), loads the page, orbits by dragging, zooms
//! with the wheel, aims by clicking, keys and saves; the saved timeline
//! then renders the frames the page showed.

use crate::util::{tool, Dir};
use fantoccini::actions::{InputSource, MouseActions, PointerAction, WheelAction, WheelActions};
use fantoccini::{Client, Locator};
use serde_json::{json, Value};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A child process killed when the test ends, however it ends.
/// Its standard output, where piped, stays open as long: a server's later
/// writes there must not fail.
struct Killed {
    child: Child,
    _stdout: Option<std::io::BufReader<std::process::ChildStdout>>,
}

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `mandelreel explore timeline` in `dir`, and the address it printed.
fn explore(dir: &Dir, timeline: &str) -> (Killed, String) {
    let mut child = dir
        .command(&["explore", timeline])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start explore");
    let mut line = String::new();
    let mut out = std::io::BufReader::new(child.stdout.take().expect("stdout"));
    std::io::BufRead::read_line(&mut out, &mut line).expect("explore's first line");
    let url = line
        .split_whitespace()
        .last()
        .expect("an address")
        .to_string();
    assert!(url.starts_with("http://127.0.0.1:"), "{line}");
    (
        Killed {
            child,
            _stdout: Some(out),
        },
        url,
    )
}

/// chromedriver on a free port, answering.
fn chromedriver() -> (Killed, String) {
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free port")
        .port();
    let child = Command::new("chromedriver")
        .arg(format!("--port={port}"))
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start chromedriver");
    let started = Instant::now();
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(
            started.elapsed() < Duration::from_secs(20),
            "chromedriver did not start"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    (
        Killed {
            child,
            _stdout: None,
        },
        format!("http://127.0.0.1:{port}"),
    )
}

/// Headless Chromium as root in a container needs no sandbox, and must not
/// reach out to the network it does not have.
/// The explorer serving one timeline of `dir`, chromedriver, and the
/// runtime a test drives a browser session with.
struct Session {
    _server: Killed,
    _driver: Killed,
    url: String,
    driver_url: String,
    profile: std::path::PathBuf,
    runtime: tokio::runtime::Runtime,
}

impl Session {
    fn open(dir: &Dir, timeline: &str) -> Session {
        let (_server, url) = explore(dir, timeline);
        let (_driver, driver_url) = chromedriver();
        Session {
            _server,
            _driver,
            url,
            driver_url,
            profile: dir.path().join("chromium-profile"),
            runtime: tokio::runtime::Runtime::new().expect("runtime"),
        }
    }

    async fn client(&self) -> Client {
        browser(&self.driver_url, &self.profile).await
    }
}

async fn browser(driver: &str, profile: &std::path::Path) -> Client {
    let args = [
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-dev-shm-usage",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--window-size=1366,800",
    ]
    .map(String::from)
    .into_iter()
    .chain([format!("--user-data-dir={}", profile.display())])
    .collect::<Vec<_>>();
    let mut caps = serde_json::Map::new();
    caps.insert("goog:chromeOptions".into(), json!({ "args": args }));
    let connector = hyper_util::client::legacy::connect::HttpConnector::new();
    fantoccini::ClientBuilder::new(connector)
        .capabilities(caps)
        .connect(driver)
        .await
        .expect("a browser session")
}

async fn js(client: &Client, script: &str) -> Value {
    client.execute(script, vec![]).await.expect(script)
}

/// Waits until the page shows every sample of its latest view.
async fn settled(client: &Client) {
    let started = Instant::now();
    let script = "const img = document.getElementById('view');
        return !moving && img.dataset.stage === 'final' && Number(img.dataset.serial) === page.serial;";
    while js(client, script).await != json!(true) {
        let shown = "const img = document.getElementById('view');
            return [document.getElementById('alert').textContent, img.dataset, page.serial, String(moving), page.dragging];";
        let shown = js(client, shown).await;
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "never settled: {shown}"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// Waits until `condition` (a JavaScript expression) holds.
async fn until(client: &Client, condition: &str) {
    let started = Instant::now();
    let script = format!("return Boolean({condition});");
    while js(client, &script).await != json!(true) {
        let alert = js(
            client,
            "return document.getElementById('alert').textContent",
        )
        .await;
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "never {condition}: {alert}"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// The pixels of the PNG the page shows.
async fn shown(client: &Client) -> Vec<u8> {
    let script = "const done = arguments[arguments.length - 1];
        page.shown.arrayBuffer().then((b) => done(Array.from(new Uint8Array(b))));";
    let bytes = client
        .execute_async(script, vec![])
        .await
        .expect("the image");
    let bytes: Vec<u8> = serde_json::from_value(bytes).expect("bytes");
    pixels(&bytes)
}

fn pixels(png_bytes: &[u8]) -> Vec<u8> {
    image::load_from_memory(png_bytes)
        .expect("a PNG")
        .to_rgb8()
        .into_raw()
}

/// The centre of the viewport element, in the window's coordinates.
async fn centre(client: &Client) -> (f64, f64) {
    let r = js(
        client,
        "const r = document.getElementById('view').getBoundingClientRect();
        return [r.left + r.width / 2, r.top + r.height / 2];",
    )
    .await;
    (r[0].as_f64().unwrap(), r[1].as_f64().unwrap())
}

/// A left-button drag from the image's centre by (dx, dy), in steps.
async fn drag(client: &Client, (dx, dy): (f64, f64)) {
    let (x, y) = centre(client).await;
    let step = Some(Duration::from_millis(40));
    let mut mouse = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x,
            y,
        })
        .then(PointerAction::Down { button: 0 });
    for i in 1..=4 {
        let f = i as f64 / 4.0;
        mouse = mouse.then(PointerAction::MoveTo {
            duration: step,
            x: x + dx * f,
            y: y + dy * f,
        });
    }
    mouse = mouse.then(PointerAction::Up { button: 0 });
    client.perform_actions(mouse).await.expect("drag");
}

async fn click_at(client: &Client, (dx, dy): (f64, f64)) {
    let (x, y) = centre(client).await;
    let mouse = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo {
            duration: None,
            x: x + dx,
            y: y + dy,
        })
        .then(PointerAction::Down { button: 0 })
        .then(PointerAction::Up { button: 0 });
    client.perform_actions(mouse).await.expect("click");
}

async fn wheel(client: &Client, delta_y: i64) {
    let (x, y) = centre(client).await;
    let mut wheel = WheelActions::new("wheel".into());
    wheel.push(WheelAction::Scroll {
        duration: None,
        x: x as i64,
        y: y as i64,
        delta_x: 0,
        delta_y,
    });
    client.perform_actions(wheel).await.expect("wheel");
}

/// The camera's distance from its target in the view.
async fn distance(client: &Client) -> f64 {
    let d = js(
        client,
        "return Math.hypot(...sub(value('camera.position'), value('camera.target')));",
    )
    .await;
    d.as_f64().expect("a distance")
}

#[test]
fn the_page_drags_zooms_keys_and_saves_what_render_renders() {
    if !tool("chromedriver", "--version") || !tool("chromium", "--version") {
        return;
    }
    let dir = Dir::new();
    let original = std::fs::read_to_string("timelines/zoom.ron")
        .expect("zoom.ron")
        .replace("size: (320, 180)", "size: (128, 72)");
    dir.write("zoom.ron", &original);
    let session = Session::open(&dir, "zoom.ron");
    let url = session.url.clone();
    let (seen_0, seen_12) = session.runtime.block_on(async {
        let client = session.client().await;
        let seen = author(&client, &url).await;
        if let Some(path) = std::env::var_os("MANDELREEL_EXPLORE_SCREENSHOT") {
            std::fs::write(path, client.screenshot().await.expect("screenshot")).expect("write");
        }
        client.close().await.expect("close the browser");
        seen
    });
    let saved = std::fs::read_to_string(dir.path().join("zoom.ron")).expect("saved");
    for comment in original
        .lines()
        .filter(|l| l.trim_start().starts_with("//"))
    {
        assert!(saved.contains(comment), "lost the comment {comment:?}");
    }
    assert!(saved.contains("\"camera.position\""), "{saved}");
    for (frame, seen) in [(0, seen_0), (12, seen_12)] {
        let out = format!("r{frame}");
        dir.ok(&[
            "render",
            "zoom.ron",
            "--frames",
            &frame.to_string(),
            "--out",
            &out,
        ]);
        let rendered = pixels(&dir.bytes(&format!("{out}/frame_{frame:05}.png")));
        assert!(
            rendered == seen,
            "frame {frame}: the saved timeline renders other pixels than the page showed"
        );
    }
}

/// Clicks the button with id `id`.
async fn press(client: &Client, id: &str) {
    let button = client.find(Locator::Id(id)).await.expect(id);
    button.click().await.expect(id);
}

/// Makes keys at frames 0 and 12 by dragging, zooming and clicking, saves,
/// and returns the pixels the page showed at each.
async fn author(client: &Client, url: &str) -> (Vec<u8>, Vec<u8>) {
    client.goto(url).await.expect("load the page");
    settled(client).await;
    let start = js(client, "return value('camera.position');").await;
    drag(client, (80.0, 30.0)).await;
    settled(client).await;
    let moved = js(client, "return page.overrides['camera.position'];").await;
    assert!(
        moved.is_array() && moved != start,
        "the drag did not orbit: {moved}"
    );
    let before = distance(client).await;
    wheel(client, -300).await;
    until(
        client,
        &format!(
            "Math.hypot(...sub(value('camera.position'), value('camera.target'))) < {before} * 0.9"
        ),
    )
    .await;
    settled(client).await;
    let seen_0 = shown(client).await;

    // K, with the image focused, keys the changes.
    let viewport = client
        .find(Locator::Id("viewport"))
        .await
        .expect("viewport");
    js(client, "document.getElementById('viewport').focus();").await;
    viewport.send_keys("k").await.expect("press K");
    until(client, "page.state.tracks.some((t) => t.name === 'camera.position') && !Object.keys(page.overrides).length").await;
    settled(client).await;
    assert!(
        shown(client).await == seen_0,
        "frame 0 keyed shows other pixels than before"
    );

    let frame = client
        .find(Locator::Id("frame"))
        .await
        .expect("frame field");
    frame.clear().await.expect("clear");
    frame.send_keys("12\u{E007}").await.expect("type a frame");
    until(client, "page.frame === 12").await;
    settled(client).await;
    drag(client, (-60.0, 0.0)).await;
    settled(client).await;
    click_at(client, (10.0, 5.0)).await;
    until(client, "page.overrides['camera.target']").await;
    settled(client).await;
    let seen_12 = shown(client).await;
    press(client, "key").await;
    until(
        client,
        "page.state.tracks.find((t) => t.name === 'camera.position').keys.length === 2",
    )
    .await;

    press(client, "save").await;
    until(client, "!page.state.dirty").await;
    (seen_0, seen_12)
}

#[test]
fn the_page_shows_auto_iterations_count_read_only() {
    if !tool("chromedriver", "--version") || !tool("chromium", "--version") {
        return;
    }
    let dir = Dir::new();
    dir.write("zoom.ron", crate::auto::ZOOM);
    let info = crate::util::stdout(&dir.ok(&["info", "zoom.ron"]));
    let count = crate::auto::counts(&info)[2];
    let session = Session::open(&dir, "zoom.ron");
    let url = session.url.clone();
    session.runtime.block_on(async {
        let client = session.client().await;
        client.goto(&url).await.expect("load the page");
        settled(&client).await;
        js(&client, "showFrame(2);").await;
        let shown = format!("Auto → {count} (target)");
        let note = "document.getElementById('auto-iterations')";
        until(
            &client,
            &format!("{note} && {note}.textContent === '{shown}'"),
        )
        .await;
        let field = "document.querySelector('.param[data-name=\"fractal.iterations\"] input')";
        assert_eq!(
            js(&client, &format!("return {field}.hidden;")).await,
            json!(true)
        );
        client.close().await.expect("close the browser");
    });
}

/// A film with no tracks: whatever is keyed first is a new track.
const STILL: &str = "(fps: 24, frames: 24, size: (64, 36), scene: (
    camera: (position: (0, 0.4, 2.6), target: (0, 0, 0), fov_degrees: 40),
    fractal: (iterations: 8),
))";

#[test]
fn a_first_key_away_from_the_start_keeps_the_films_start() {
    if !tool("chromedriver", "--version") || !tool("chromium", "--version") {
        return;
    }
    let dir = Dir::new();
    dir.write("still.ron", STILL);
    let session = Session::open(&dir, "still.ron");
    let url = session.url.clone();
    let said = session.runtime.block_on(async {
        let client = session.client().await;
        client.goto(&url).await.expect("load the page");
        settled(&client).await;
        js(&client, "showFrame(12);").await;
        until(&client, "page.frame === 12").await;
        settled(&client).await;
        drag(&client, (60.0, 0.0)).await;
        until(&client, "page.overrides['camera.position']").await;
        press(&client, "key").await;
        let track = "page.state.tracks.find((t) => t.name === 'camera.position')";
        until(&client, &format!("{track} && {track}.keys.length === 2")).await;
        let said = js(
            &client,
            "return document.getElementById('message').textContent;",
        )
        .await;
        press(&client, "save").await;
        until(&client, "!page.state.dirty").await;
        client.close().await.expect("close the browser");
        said.as_str().unwrap_or_default().to_string()
    });
    assert!(said.contains("frame 0"), "the page said: {said}");
    // Frame 0 renders as before the key; frame 12 does not.
    dir.write("before.ron", STILL);
    for (timeline, out) in [("before.ron", "b"), ("still.ron", "a")] {
        dir.ok(&["render", timeline, "--frames", "0..=12", "--out", out]);
    }
    let frame = |out: &str, n: u32| dir.bytes(&format!("{out}/frame_{n:05}.png"));
    assert!(
        pixels(&frame("a", 0)) == pixels(&frame("b", 0)),
        "frame 0 moved"
    );
    assert!(
        pixels(&frame("a", 12)) != pixels(&frame("b", 12)),
        "frame 12 kept"
    );
}

/// A still whose target is held in digits, as a deep zoom's is.
const HELD: &str = r#"(fps: 24, frames: 2, size: (64, 36), scene: (
    camera: (position: (0.30000000000000004, 0.4, 2.6), target: ("0.1", "-0.110408951367381233764950538762334472", "0"), fov_degrees: 40),
    fractal: (iterations: 8),
))"#;

#[test]
fn digits_typed_into_a_field_are_saved_as_typed() {
    if !tool("chromedriver", "--version") || !tool("chromium", "--version") {
        return;
    }
    const TYPED: &str = "0.1000000000000000000000000000001";
    let dir = Dir::new();
    dir.write("held.ron", HELD);
    let session = Session::open(&dir, "held.ron");
    let url = session.url.clone();
    let shown = session.runtime.block_on(async {
        let client = session.client().await;
        client.goto(&url).await.expect("load the page");
        settled(&client).await;
        let fields = ".param[data-name=\"camera.target\"] input";
        let y = format!("return document.querySelectorAll('{fields}')[1].value;");
        let shown = js(&client, &y).await;
        let x = client
            .find(Locator::Css(fields))
            .await
            .expect("the x field");
        x.clear().await.expect("clear x");
        x.send_keys(TYPED).await.expect("type x");
        js(&client, "document.activeElement.blur();").await;
        until(&client, "page.typed['camera.target']").await;
        // A plain point's field of f64's own 17 digits stays a number.
        let position = ".param[data-name=\"camera.position\"] input";
        let fields = client
            .find_all(Locator::Css(position))
            .await
            .expect("position");
        fields[1].clear().await.expect("clear y");
        fields[1].send_keys("0.5").await.expect("type y");
        js(&client, "document.activeElement.blur();").await;
        until(
            &client,
            "page.overrides['camera.position'] && page.overrides['camera.position'][1] === 0.5",
        )
        .await;
        press(&client, "set-scene").await;
        until(
            &client,
            "page.state.dirty && !page.overrides['camera.target']",
        )
        .await;
        press(&client, "save").await;
        until(&client, "!page.state.dirty").await;
        client.close().await.expect("close the browser");
        shown
    });
    // The field showed the digits the file holds, not their f64.
    assert_eq!(shown, json!("-0.110408951367381233764950538762334472"));
    let saved = String::from_utf8(dir.bytes("held.ron")).expect("text");
    // Every digit typed, and the untouched components as they were written.
    let target = format!("(\"{TYPED}\", \"-0.110408951367381233764950538762334472\", \"0\")");
    assert!(saved.contains(&target), "{saved}");
    assert!(saved.contains("(0.30000000000000004, 0.5, 2.6)"), "{saved}");
}

/// deep_zoom.ron's last shot as a still: a zoom track holds the camera
/// 1e-30 below a target written in digits, nearer than f64 keeps apart.
const DEEP: &str = r#"(fps: 24, frames: 2, size: (48, 27), scene: (
    camera: (position: (0.575, -2.4, 0.482), target: ("0", "-1.10408951367381233764950538762334472132532660078012416551453", "0"), up: (0, 1, 0), fov_degrees: 40),
    fractal: (iterations: 60),
), tracks: {"camera.distance": (keys: [(time: 0, value: 1e-30)])})"#;

#[test]
fn a_deep_camera_orbits_and_zooms_by_keys_in_its_digits() {
    if !tool("chromedriver", "--version") || !tool("chromium", "--version") {
        return;
    }
    let dir = Dir::new();
    dir.write("deep.ron", DEEP);
    let session = Session::open(&dir, "deep.ron");
    let url = session.url.clone();
    session.runtime.block_on(async {
        let client = session.client().await;
        client.goto(&url).await.expect("load the page");
        settled(&client).await;
        let viewport = client
            .find(Locator::Id("viewport"))
            .await
            .expect("viewport");
        js(&client, "document.getElementById('viewport').focus();").await;
        // Left turns the camera 0.16 radians about up; W brings it 0.8 as near.
        viewport.send_keys("\u{E012}").await.expect("press left");
        until(&client, "page.typed['camera.position']").await;
        settled(&client).await;
        viewport.send_keys("w").await.expect("press W");
        until(&client, "page.overrides['camera.distance']").await;
        settled(&client).await;
        let alert = js(
            &client,
            "return document.getElementById('alert').textContent;",
        )
        .await;
        assert_eq!(alert, json!(""), "the moved view was refused");
        viewport.send_keys("k").await.expect("press K");
        until(
            &client,
            "page.state.dirty && !Object.keys(page.overrides).length",
        )
        .await;
        press(&client, "save").await;
        until(&client, "!page.state.dirty").await;
        client.close().await.expect("close the browser");
    });
    let away = |text: &str| {
        let path = std::path::Path::new("deep.ron");
        let timeline = mandelreel::timeline::Timeline::parse(text, path).expect("a timeline");
        timeline.scene_at(0).camera.relative_position()
    };
    let saved = String::from_utf8(dir.bytes("deep.ron")).expect("text");
    let (before, after) = (away(DEEP), away(&saved));
    let ratio = after.length() / before.length();
    assert!((ratio - 0.8).abs() < 1e-9, "{before} became {after}");
    let (b, a) = (before.normalize(), after.normalize());
    assert!(
        (a.y - b.y).abs() < 1e-9,
        "turned off the up axis: {b} to {a}"
    );
    let turn = (a.z.atan2(a.x) - b.z.atan2(b.x)).abs();
    assert!(
        (turn - 0.16).abs() < 1e-6,
        "turned {turn} radians: {b} to {a}"
    );
}

/// Every parameter's name whole, nothing wider than the window, disabled
/// buttons unlike enabled ones, and what the page says kept to the latest:
/// at a laptop's and a desktop's size. With `MANDELREEL_EXPLORE_SCREENSHOTS`
/// set to a folder, the page is saved there at each size.
#[test]
fn the_page_reads_whole_at_laptop_and_desktop_sizes() {
    if !tool("chromedriver", "--version") || !tool("chromium", "--version") {
        return;
    }
    let dir = Dir::new();
    let effects = std::fs::read_to_string("timelines/effects.ron").expect("effects.ron");
    dir.write("effects.ron", &effects);
    let session = Session::open(&dir, "effects.ron");
    let url = session.url.clone();
    session.runtime.block_on(async {
        let client = session.client().await;
        for (width, height) in [(1366u32, 768u32), (1920, 1080)] {
            client.set_window_size(width, height).await.expect("window size");
            client.goto(&url).await.expect("load the page");
            settled(&client).await;
            let cut = js(&client, "return [...document.querySelectorAll('.param:not([hidden]) label')]
                .filter((l) => l.scrollWidth > l.clientWidth + 1).map((l) => l.title);").await;
            assert_eq!(cut, json!([]), "{width}x{height}: names cut");
            let wide = js(&client, "return document.documentElement.scrollWidth - window.innerWidth;").await;
            assert!(wide.as_f64() <= Some(0.0), "{width}x{height}: {wide} px too wide");
            let colours = js(&client, "return ['key', 'save'].map((id) => getComputedStyle(document.getElementById(id)).color);").await;
            assert_ne!(colours[0], colours[1], "a disabled button looks like an enabled one");
            // The full-size stages' progress comes back by event.
            js(&client, "refresh();").await;
            until(&client, "document.getElementById('progress').title.startsWith('final')").await;
            settled(&client).await;
            if let Some(folder) = std::env::var_os("MANDELREEL_EXPLORE_SCREENSHOTS") {
                let png = client.screenshot().await.expect("screenshot");
                let path = std::path::Path::new(&folder).join(format!("explore-{width}x{height}.png"));
                std::fs::write(path, png).expect("write the screenshot");
            }
        }
        // A frame past the end is shown as the last, and said so; an error
        // then replaces that line rather than standing beside it.
        js(&client, "showFrame(9999);").await;
        until(&client, "document.getElementById('message').textContent.includes('frames 0 to')").await;
        js(&client, "document.getElementById('size').value = '7x'; refresh();").await;
        until(&client, "!document.getElementById('alert').hidden").await;
        let message = js(&client, "return document.getElementById('message').textContent;").await;
        assert_eq!(message, json!(""), "a stale line beside the error");
        client.close().await.expect("close the browser");
    });
}
