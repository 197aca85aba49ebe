//! The web demo in a real headless Chromium: `scripts/web.sh --build-only` builds the page,
//! Python's `http.server` serves it on 127.0.0.1, chromedriver drives the browser (WebGPU on
//! SwiftShader through `--enable-unsafe-webgpu`). A test that cannot build the page or start
//! the browser fails; it never skips.
//!
//! - the hall with 1,024 animated lights reaches `manylight: ready` within 60 s, the stats count
//!   1,030 lights on WebGPU, no pixel is NaN and the canvas is not blank;
//! - the page's image of a fixed-clock frame equals the native renderer's (FLIP, the thresholds
//!   of the pipeline comparisons), with clustered forward and clustered deferred, and its
//!   passes are native's;
//! - 100,000 sphere-shell lights render with no device error;
//! - a bad URL parameter shows its error on the page and in `manylight.error()`.
//!
//! Headless Chromium's WebGPU on SwiftShader loses its device as soon as a WebGPU canvas
//! presents a frame, so the pages here show their frames through read-back
//! (`present=read-back`), which renders exactly as the canvas path does.

mod support;

use base64::Engine;
use image::RgbaImage;
use manylight::prelude::*;
use manylight_web::demo::DemoScene;
use manylight_web::options::WebOptions;
use serde_json::{Value, json};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Mutex, MutexGuard, OnceLock};
use std::time::{Duration, Instant};

/// How long the page may take to show its first frame (the acceptance bound).
const READY_TIMEOUT: Duration = Duration::from_secs(60);

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The built page (`target/web`), built once per test binary.
fn page_dir() -> &'static Path {
    static BUILT: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    let built = BUILT.get_or_init(|| {
        let status = Command::new("bash")
            .arg(root().join("scripts/web.sh"))
            .arg("--build-only")
            .current_dir(root())
            .status()
            .map_err(|e| format!("cannot run scripts/web.sh: {e}"))?;
        if !status.success() {
            return Err(format!("scripts/web.sh --build-only failed ({status})"));
        }
        Ok(root().join("target/web"))
    });
    match built {
        Ok(dir) => dir,
        Err(e) => panic!("the web page could not be built: {e}"),
    }
}

/// A free port on 127.0.0.1.
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .expect("a free local port")
}

/// A child process killed when dropped.
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Waits until something listens on `port`.
fn wait_for_port(port: u16, what: &str) {
    let deadline = Instant::now() + Duration::from_secs(20);
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(Instant::now() < deadline, "{what} did not start listening on 127.0.0.1:{port}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The page server and chromedriver, shared by the tests of this binary (one browser session
/// at a time: SwiftShader renders on the same two cores as everything else).
struct Browser {
    page_port: u16,
    driver_port: u16,
    _server: Killed,
    _driver: Killed,
}

fn browser() -> MutexGuard<'static, Browser> {
    static BROWSER: OnceLock<Mutex<Browser>> = OnceLock::new();
    let browser = BROWSER.get_or_init(|| {
        let dir = page_dir();
        let page_port = free_port();
        let server = Command::new("python3")
            .args(["-m", "http.server", "--bind", "127.0.0.1", "--directory"])
            .arg(dir)
            .arg(page_port.to_string())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start python3 -m http.server (install python3): {e}"));
        let server = Killed(server);
        let driver_port = free_port();
        let driver = Command::new(chromedriver())
            .arg(format!("--port={driver_port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start chromedriver (scripts/setup.sh installs it): {e}"));
        let driver = Killed(driver);
        wait_for_port(page_port, "the page server");
        wait_for_port(driver_port, "chromedriver");
        Mutex::new(Browser { page_port, driver_port, _server: server, _driver: driver })
    });
    browser.lock().unwrap_or_else(|e| e.into_inner())
}

fn chromedriver() -> String {
    std::env::var("CHROMEDRIVER").unwrap_or_else(|_| "chromedriver".into())
}

/// The Chromium binary chromedriver starts: `CHROME_BIN`, or Debian's.
fn chromium() -> String {
    std::env::var("CHROME_BIN").unwrap_or_else(|_| "/usr/lib/chromium/chromium".into())
}

/// One browser session on a page (WebDriver over HTTP), ended when dropped.
struct Session {
    base: String,
}

impl Session {
    /// Opens headless Chromium with WebGPU (`webgpu`) or without it, at `query`.
    fn open(browser: &Browser, query: &str, webgpu: bool) -> Session {
        let mut args =
            vec!["--headless=new", "--no-sandbox", "--window-size=800,600", "--disable-gpu-sandbox"];
        if webgpu {
            args.push("--enable-unsafe-webgpu");
        }
        let caps = json!({"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {"binary": chromium(), "args": args},
        }}});
        let url = format!("http://127.0.0.1:{}/session", browser.driver_port);
        let reply = post(&url, &caps);
        let id = reply["value"]["sessionId"]
            .as_str()
            .unwrap_or_else(|| panic!("chromedriver started no browser session: {reply}"));
        let session = Session { base: format!("http://127.0.0.1:{}/session/{id}", browser.driver_port) };
        post(
            &format!("{}/url", session.base),
            &json!({"url": format!("http://127.0.0.1:{}/{query}", browser.page_port)}),
        );
        session
    }

    /// Runs `script` (a function body) in the page and returns its value.
    fn eval(&self, script: &str) -> Value {
        post(&format!("{}/execute/sync", self.base), &json!({"script": script, "args": []}))["value"].take()
    }

    /// Polls `script` until it returns something other than null or `timeout` passes; the page's
    /// error fails the test at once.
    fn wait_for(&self, script: &str, timeout: Duration, what: &str) -> Value {
        let start = Instant::now();
        loop {
            let error = self.eval("return manylight.error() ?? null;");
            assert!(error.is_null(), "the page failed while waiting for {what}: {error}");
            let value = self.eval(script);
            if !value.is_null() && value != Value::Bool(false) {
                return value;
            }
            assert!(start.elapsed() < timeout, "no {what} within {} s", timeout.as_secs());
            std::thread::sleep(Duration::from_millis(250));
        }
    }

    fn wait_ready(&self) -> Duration {
        let start = Instant::now();
        self.wait_for(
            "return document.title === 'manylight: ready';",
            READY_TIMEOUT,
            "`manylight: ready` title",
        );
        start.elapsed()
    }

    /// The page as the browser shows it.
    fn screenshot(&self) -> RgbaImage {
        let reply = ureq::get(&format!("{}/screenshot", self.base))
            .call()
            .expect("screenshot")
            .into_body()
            .read_json::<Value>();
        let data =
            reply.expect("screenshot JSON")["value"].as_str().map(str::to_owned).expect("screenshot data");
        decode_png(&data)
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        let _ = ureq::delete(&self.base).call();
    }
}

fn post(url: &str, body: &Value) -> Value {
    let reply = ureq::post(url)
        .config()
        .http_status_as_error(false)
        .timeout_global(Some(Duration::from_secs(300)))
        .build()
        .send_json(body)
        .unwrap_or_else(|e| panic!("WebDriver request {url} failed: {e}"));
    reply.into_body().read_json::<Value>().unwrap_or_else(|e| panic!("WebDriver reply of {url}: {e}"))
}

fn decode_png(base64_png: &str) -> RgbaImage {
    let bytes = base64::engine::general_purpose::STANDARD.decode(base64_png).expect("base64 PNG");
    image::load_from_memory(&bytes).expect("a PNG").to_rgba8()
}

/// The last frame of the page's stats.
fn last_frame(session: &Session) -> Value {
    session.eval("return manylight.stats()")["last_frame"].take()
}

#[test]
fn hall_with_1024_lights_reaches_ready_on_webgpu() {
    let browser = browser();
    let session = Session::open(&browser, "?lights=1024&present=read-back", true);
    let took = session.wait_ready();
    println!("ready after {:.1} s", took.as_secs_f64());
    let stats = session.wait_for(
        "const s = manylight.stats(); return s && s.last_frame && s.last_frame.light_count === 1030 ? s : null;",
        Duration::from_secs(30),
        "a frame with 1,030 lights",
    );
    assert_eq!(stats["backend"], "webgpu", "{stats}");
    let frame = &stats["last_frame"];
    assert_eq!(frame["pipeline"], "clustered-forward");
    assert_eq!(frame["nonfinite_pixels"], 0, "NaN or infinite pixels: {frame}");
    assert_lit(&session.screenshot(), "web_hall");
}

/// Panics unless the page's screenshot `shot` shows the lit hall: many distinct colours and a
/// mean brightness well above black (else writes it to `target/image-tests/NAME.actual.png`).
fn assert_lit(shot: &RgbaImage, name: &str) {
    let mut colours: Vec<[u8; 3]> = shot.pixels().map(|p| [p[0] >> 3, p[1] >> 3, p[2] >> 3]).collect();
    colours.sort_unstable();
    colours.dedup();
    let mean = shot.pixels().map(|p| u64::from(p[0]) + u64::from(p[1]) + u64::from(p[2])).sum::<u64>() as f64
        / (shot.width() * shot.height() * 3) as f64;
    if colours.len() < 200 || mean < 10.0 {
        let path = support::output_dir().join(format!("{name}.actual.png"));
        let _ = shot.save(&path);
        panic!("the canvas looks blank: {} colours, mean {mean:.1} ({})", colours.len(), path.display());
    }
}

/// The page's image of update 3 on a fixed clock against the native renderer's third frame of
/// the same scene (`manylight_web::demo::add_scene`), and their passes.
fn page_matches_native(pipeline: &str) {
    let query = format!(
        "?lights=256&pipeline={pipeline}&size=128x128&overlay=off&clock=fixed&capture=3&present=read-back"
    );
    let options = WebOptions::from_query(&query).expect("a valid query");
    let expected = {
        let _gpu = support::gpu();
        manylight::app::headless::render_headless(UVec2::new(128, 128), 3, |app| {
            manylight_web::demo::add_scene(app, &options, DemoScene::Hall, 1.0);
        })
        .expect("the native frame")
    };
    // The native frame is held to its stored reference (a changed shader fails here).
    support::assert_matches_reference(&format!("web_hall_{pipeline}"), &expected.image, support::STRICT);
    page_matches(&format!("web_{pipeline}"), &query, &expected);
}

/// The page's capture for `query` against the native `expected` frame (another device:
/// `CROSS_DEVICE`), and their passes.
fn page_matches(name: &str, query: &str, expected: &manylight::app::headless::HeadlessFrame) {
    let browser = browser();
    let session = Session::open(&browser, query, true);
    session.wait_ready();
    let url = session.wait_for("return manylight.capture();", Duration::from_secs(60), "the captured image");
    let data = url.as_str().and_then(|u| u.strip_prefix("data:image/png;base64,")).expect("a PNG data URL");
    let actual = decode_png(data);
    let flip = support::assert_similar(name, &expected.image, &actual, support::CROSS_DEVICE);
    println!("{name}: page against native FLIP mean {:.4}, p99 {:.4}", flip.mean, flip.p99);
    let names = |frame: &Value| -> Vec<String> {
        frame["passes"]
            .as_array()
            .map_or(Vec::new(), |p| p.iter().filter_map(|p| p["name"].as_str().map(str::to_owned)).collect())
    };
    let native = serde_json::to_value(expected.stats.document()).expect("stats JSON");
    assert_eq!(
        names(&last_frame(&session)),
        names(&native["last_frame"]),
        "the page ran other passes than native"
    );
}

/// With WebGPU disabled (Chromium without `--enable-unsafe-webgpu`: `navigator.gpu` gives no
/// adapter) the page falls back to WebGL2, through ANGLE on SwiftShader: it reaches `ready`
/// with the hall's 1,024 rig lights (1,030 with the hall's own), says `webgl2` with no NaN
/// pixel, and its fixed-clock image of update 3 is within `CROSS_DEVICE` of the native
/// clustered forward frame. No `present=read-back`: WebGL2 always shows its frames so.
#[test]
fn webgl2_fallback_with_1024_lights_matches_native() {
    let query = "?lights=1024&size=128x128&overlay=off&clock=fixed&capture=3";
    let options = WebOptions::from_query(query).expect("a valid query");
    let expected = {
        let _gpu = support::gpu();
        manylight::app::headless::render_headless(UVec2::new(128, 128), 3, |app| {
            manylight_web::demo::add_scene(app, &options, DemoScene::Hall, 1.0);
        })
        .expect("the native frame")
    };
    let browser = browser();
    let session = Session::open(&browser, query, false);
    let took = session.wait_ready();
    println!("WebGL2: ready after {:.1} s", took.as_secs_f64());
    let stats = session.wait_for(
        "const s = manylight.stats(); return s && s.last_frame && s.last_frame.light_count === 1030 ? s : null;",
        Duration::from_secs(30),
        "a frame with 1,030 lights",
    );
    assert_eq!(stats["backend"], "webgl2", "{stats}");
    let frame = &stats["last_frame"];
    assert_eq!(frame["pipeline"], "clustered-forward", "{frame}");
    assert_eq!(frame["nonfinite_pixels"], 0, "NaN or infinite pixels: {frame}");
    let url = session.wait_for("return manylight.capture();", Duration::from_secs(60), "the captured image");
    let data = url.as_str().and_then(|u| u.strip_prefix("data:image/png;base64,")).expect("a PNG data URL");
    let actual = decode_png(data);
    let flip = support::assert_similar("web_webgl2_hall", &expected.image, &actual, support::CROSS_DEVICE);
    println!("web_webgl2_hall: page against native FLIP mean {:.4}, p99 {:.4}", flip.mean, flip.p99);
}

/// `backend=webgl2` renders with WebGL2 where WebGPU is there too, and the page's canvas
/// (filling the page; WebGL2 shows its frames through read-back) shows the lit hall.
#[test]
fn backend_webgl2_is_chosen_over_webgpu() {
    let browser = browser();
    let session = Session::open(&browser, "?backend=webgl2", true);
    let took = session.wait_ready();
    println!("backend=webgl2: ready after {:.1} s", took.as_secs_f64());
    let stats = session.wait_for(
        "const s = manylight.stats(); return s && s.last_frame && s.last_frame.light_count === 1030 ? s : null;",
        Duration::from_secs(30),
        "a frame with 1,030 lights",
    );
    assert_eq!(stats["backend"], "webgl2", "{stats}");
    assert_eq!(stats["last_frame"]["nonfinite_pixels"], 0, "{stats}");
    // A few frames later, so that one has been read back and shown.
    std::thread::sleep(Duration::from_secs(2));
    assert_lit(&session.screenshot(), "web_webgl2_page");
}

#[test]
fn clustered_forward_image_equals_native() {
    page_matches_native("clustered-forward");
}

#[test]
fn clustered_deferred_image_equals_native() {
    page_matches_native("clustered-deferred");
}

/// A glTF file with an external buffer and image, fetched by the page from `assets/`, renders
/// as the native renderer renders the file loaded from disk.
#[test]
fn a_gltf_scene_is_fetched_and_matches_native() {
    let scene = "BoxTextured/BoxTextured.gltf";
    let query =
        format!("?scene={scene}&lights=64&size=128x128&overlay=off&clock=fixed&capture=3&present=read-back");
    let options = WebOptions::from_query(&query).expect("a valid query");
    let loaded = manylight::scene::load_gltf(&root().join("assets").join(scene), &LoadOptions::default())
        .expect("the asset loads");
    let expected = {
        let _gpu = support::gpu();
        manylight::app::headless::render_headless(UVec2::new(128, 128), 3, |app| {
            manylight_web::demo::add_scene(app, &options, DemoScene::Loaded(Box::new(loaded)), 1.0);
        })
        .expect("the native frame")
    };
    assert_eq!(expected.stats.last.as_ref().map(|f| f.light_count), Some(64));
    page_matches("web_gltf_box", &query, &expected);
}

#[test]
fn a_gltf_scene_that_is_not_there_is_an_error_on_the_page() {
    let browser = browser();
    let session = Session::open(&browser, "?scene=Missing/missing.glb&present=read-back", true);
    let message = wait_error(&session, "a missing glTF file");
    assert!(message.contains("cannot fetch `assets/Missing/missing.glb`: HTTP 404"), "{message}");
}

#[test]
fn sphere_shell_with_100000_lights_renders() {
    let browser = browser();
    let session =
        Session::open(&browser, "?scene=sphere-shell&lights=100000&size=256x256&present=read-back", true);
    session.wait_ready();
    let frame = last_frame(&session);
    assert_eq!(frame["light_count"], 100_000, "{frame}");
    assert_eq!(frame["nonfinite_pixels"], 0, "{frame}");
}

#[test]
fn a_bad_parameter_is_shown_on_the_page() {
    let browser = browser();
    let session = Session::open(&browser, "?lights=lots", true);
    let message = wait_error(&session, "?lights=lots");
    assert!(message.contains("`lights=lots`"), "{message}");
    let shown = session
        .eval("const e = document.getElementById('manylight-error'); return [e.className, e.textContent];");
    assert_eq!(shown[0], "shown", "{shown}");
    assert_eq!(shown[1], message.as_str());
}

/// The page's error message, once it has one (at most 30 s).
fn wait_error(session: &Session, what: &str) -> String {
    let start = Instant::now();
    loop {
        let error = session.eval("return manylight.error() ?? null;");
        if let Some(message) = error.as_str() {
            return message.to_string();
        }
        assert!(start.elapsed() < Duration::from_secs(30), "no error for {what}");
        std::thread::sleep(Duration::from_millis(200));
    }
}
