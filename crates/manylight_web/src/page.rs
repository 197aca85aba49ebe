//! The page side: starts the app in the page's canvas, and answers the page contract.
//!
//! 1. `start` (run when the module is initialised) parses the URL query, fetches and loads the
//!    glTF file the `scene` parameter names (if it names one), picks the backend (WebGPU where
//!    `navigator.gpu` gives an adapter, otherwise WebGL2, or what `backend` asks for), builds
//!    the app with the manylight plugin drawing into `<canvas id="manylight">`, and hands it to
//!    the page's event loop. The device is requested asynchronously; the app updates once it
//!    arrives. WebGL2 renders with the texture-list path ([`crate::webgl`]) and shows its frames
//!    through read-back.
//! 2. Each update, `publish` keeps the last frame's statistics as JSON, sets
//!    `document.title` to `manylight: ready` after the first frame, and shows a failure.
//! 3. `stats()`, `error()` and `capture()` are what `window.manylight` calls (`index.html`).

use crate::controls::{FlyInput, fly};
use crate::demo::{DemoScene, add_scene};
use crate::options::{AssetPath, WebBackend, WebOptions, WebPresent, WebScene};
use crate::readback_canvas::{DisplaySlot, ReadBackSink};
use crate::webgl::TextureListSink;
use base64::Engine;
use manylight::app::backend::{FrameSink, RenderBackend};
use manylight::app::render_world::HeadlessRenderer;
use manylight::app::window::WindowConfig;
use manylight::app::{FrameStats, HeadlessCapture, RenderFailure};
use manylight::prelude::*;
use manylight::render::GpuContext;
use manylight::render::texture_lists::TextureListRenderer;
use manylight::render::wgpu;
use std::cell::RefCell;
use std::rc::Rc;
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::*;

/// The title the page gets once the first frame's statistics arrived.
pub const READY_TITLE: &str = "manylight: ready";

/// What the page contract reads; the app writes it each update.
#[derive(Default)]
struct PageState {
    stats: Option<String>,
    stats_frame: Option<u64>,
    error: Option<String>,
    capture: Option<String>,
}

/// The user's input since the last update, gathered by the DOM listeners.
#[derive(Default)]
struct PointerKeys {
    /// `KeyboardEvent.code` of the keys held.
    held: std::collections::BTreeSet<String>,
    shift: bool,
    /// A mouse button is held over the canvas.
    dragging: bool,
    /// Pixels dragged since the last update.
    drag: Vec2,
}

thread_local! {
    static PAGE: RefCell<PageState> = RefCell::new(PageState::default());
    static INPUT: RefCell<PointerKeys> = RefCell::new(PointerKeys::default());
}

/// The last frame's statistics as JSON (`manylight render --stats-json`'s document, plus
/// `backend`: `webgpu` or `webgl2`); `undefined` before the first frame.
#[wasm_bindgen]
pub fn stats() -> Option<String> {
    PAGE.with(|p| p.borrow().stats.clone())
}

/// The first error the page met (a bad URL parameter, a device that could not be had, a failed
/// frame); `undefined` while there is none.
#[wasm_bindgen]
pub fn error() -> Option<String> {
    PAGE.with(|p| p.borrow().error.clone())
}

/// The image of the update the `capture` parameter named, as a PNG data URL, once it has
/// been read back; `undefined` until then.
#[wasm_bindgen]
pub fn capture() -> Option<String> {
    PAGE.with(|p| p.borrow().capture.clone())
}

/// Records `message` as the page's error (the first one stays) and shows it on the page.
fn fail(message: &str) {
    let first = PAGE.with(|p| {
        let mut p = p.borrow_mut();
        let first = p.error.is_none();
        p.error.get_or_insert_with(|| message.to_string());
        first
    });
    if !first {
        return;
    }
    web_sys::console::error_1(&JsValue::from_str(message));
    let element =
        web_sys::window().and_then(|w| w.document()).and_then(|d| d.get_element_by_id("manylight-error"));
    if let Some(element) = element {
        element.set_text_content(Some(message));
        let _ = element.set_attribute("class", "shown");
    }
}

/// Writes log lines to the browser's console (warnings and errors as such).
struct ConsoleWriter(Vec<u8>);

impl std::io::Write for ConsoleWriter {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0.extend_from_slice(bytes);
        Ok(bytes.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Drop for ConsoleWriter {
    fn drop(&mut self) {
        let line = String::from_utf8_lossy(&self.0);
        let line = JsValue::from_str(line.trim_end());
        if self.0.starts_with(b"ERROR") {
            web_sys::console::error_1(&line);
        } else if self.0.starts_with(b" WARN") {
            web_sys::console::warn_1(&line);
        } else {
            web_sys::console::log_1(&line);
        }
    }
}

/// Runs when the module is initialised.
#[wasm_bindgen(start)]
pub fn start() {
    std::panic::set_hook(Box::new(|info| fail(&format!("manylight stopped: {info}"))));
    // `info` and above to the console (the page has no clock for timestamps: std's panics).
    let _ = tracing_subscriber::fmt()
        .with_writer(|| ConsoleWriter(Vec::new()))
        .with_ansi(false)
        .without_time()
        .with_max_level(tracing::Level::INFO)
        .try_init();
    if let Err(message) = run() {
        fail(&message);
    }
}

fn run() -> Result<(), String> {
    let window = web_sys::window().ok_or("no window: manylight_web runs in a page")?;
    let document = window.document().ok_or("the window has no document")?;
    let query = window.location().search().map_err(|e| format!("cannot read the URL: {e:?}"))?;
    let options = WebOptions::from_query(&query).map_err(|e| e.to_string())?;
    let canvas = document
        .get_element_by_id("manylight")
        .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok())
        .ok_or("the page has no <canvas id=\"manylight\">")?;
    if let Some(size) = options.size {
        // A fixed size instead of the page's: the page's CSS sizes the canvas by its class.
        let style = format!("width: {}px; height: {}px", size.x, size.y);
        canvas.set_attribute("style", &style).map_err(|e| format!("cannot size the canvas: {e:?}"))?;
        canvas.set_attribute("class", "fixed").map_err(|e| format!("cannot size the canvas: {e:?}"))?;
    }
    listen_for_input(&canvas)?;
    wasm_bindgen_futures::spawn_local(async move {
        let started = async {
            let scene = match (DemoScene::built_in(&options.scene), &options.scene) {
                (Some(scene), _) => scene,
                (None, WebScene::Gltf(path)) => DemoScene::Loaded(Box::new(load_asset(path).await?)),
                (None, _) => unreachable!("every scene but a glTF file is built in"),
            };
            let webgl2 = uses_webgl2(options.backend).await;
            start_app(options, canvas, scene, webgl2)
        };
        if let Err(message) = started.await {
            fail(&message);
        }
    });
    Ok(())
}

/// Whether the page renders with WebGL2: asked for, or (`auto`) the browser's `navigator.gpu`
/// gives no WebGPU adapter.
async fn uses_webgl2(backend: WebBackend) -> bool {
    match backend {
        WebBackend::WebGl2 => true,
        WebBackend::WebGpu => false,
        WebBackend::Auto => {
            let instance = manylight::render::context::new_instance();
            let webgpu = instance.request_adapter(&wgpu::RequestAdapterOptions::default()).await.is_ok();
            if !webgpu {
                tracing::info!("no WebGPU adapter: rendering with WebGL2");
            }
            !webgpu
        }
    }
}

/// Fetches the glTF file at `path` and every file it refers to, and loads it.
async fn load_asset(path: &AssetPath) -> Result<Scene, String> {
    use manylight::scene::{FetchedFiles, load_gltf_fetched, referenced_files};
    let url = path.url();
    let options = LoadOptions::default();
    let named = std::path::Path::new(&url);
    let failed = |e: manylight::scene::SceneError| format!("scene `{}` did not load: {e}", path.as_str());
    let bytes = fetch_bytes(&url, options.max_glb_bytes.max(options.max_json_bytes)).await?;
    let mut files = FetchedFiles::new();
    let folder = &url[..url.rfind('/').map_or(0, |i| i + 1)];
    for file in referenced_files(named, &bytes, &options).map_err(failed)? {
        let data = fetch_bytes(&format!("{folder}{}", file.uri), options.max_buffer_bytes).await?;
        files.insert(file.name, data);
    }
    load_gltf_fetched(named, &bytes, &files, &options).map_err(failed)
}

/// The body of the response to a GET of `url` (relative to the page), refused when the server
/// answers with an error or it is over `limit` bytes.
async fn fetch_bytes(url: &str, limit: u64) -> Result<Vec<u8>, String> {
    use wasm_bindgen_futures::JsFuture;
    let cannot = |why: String| format!("cannot fetch `{url}`: {why}");
    let window = web_sys::window().ok_or_else(|| cannot("no window".into()))?;
    let response: web_sys::Response = JsFuture::from(window.fetch_with_str(url))
        .await
        .map_err(|e| cannot(format!("{e:?}")))?
        .dyn_into()
        .map_err(|_| cannot("the answer is not a response".into()))?;
    if !response.ok() {
        return Err(cannot(format!("HTTP {} {}", response.status(), response.status_text())));
    }
    let too_large = |size: u64| cannot(format!("it is {size} bytes, over the limit of {limit}"));
    // The declared length is refused before the body is read; the body is checked again.
    let declared =
        response.headers().get("content-length").ok().flatten().and_then(|l| l.parse::<u64>().ok());
    if let Some(size) = declared.filter(|&size| size > limit) {
        return Err(too_large(size));
    }
    let body = response.array_buffer().map_err(|e| cannot(format!("{e:?}")))?;
    let body = JsFuture::from(body).await.map_err(|e| cannot(format!("{e:?}")))?;
    let array = js_sys::Uint8Array::new(&body);
    if u64::from(array.length()) > limit {
        return Err(too_large(u64::from(array.length())));
    }
    Ok(array.to_vec())
}

/// Builds the app for `options` showing `scene` in `canvas` (on WebGL2 when `webgl2`), and
/// starts it.
fn start_app(
    options: WebOptions,
    canvas: web_sys::HtmlCanvasElement,
    scene: DemoScene,
    webgl2: bool,
) -> Result<(), String> {
    // WebGL2 renders offscreen and shows its frames through read-back (no overlay).
    let present = if webgl2 { WebPresent::ReadBack } else { options.present };
    let (width, height) = match options.size {
        Some(size) => (size.x, size.y),
        None => (canvas.client_width().max(1) as u32, canvas.client_height().max(1) as u32),
    };
    let mut app = App::new();
    match present {
        WebPresent::Canvas => {
            let config = WindowConfig {
                title: "manylight".into(),
                width,
                height,
                overlay: options.overlay,
                canvas: Some(canvas.clone()),
                ..WindowConfig::default()
            };
            app.add_plugins(ManyLightPlugin::window(config));
        }
        WebPresent::ReadBack => {
            app.add_plugins(ManyLightPlugin::headless(UVec2::new(width, height)))
                .insert_resource(TimeUpdateStrategy::Automatic);
        }
    }
    add_scene(&mut app, &options, scene, width as f32 / height as f32);
    app.insert_resource(CaptureAt(options.capture))
        .insert_resource(Presenting(present))
        .add_systems(Update, fly_camera)
        .add_systems(First, arm_capture)
        .add_systems(Last, publish.after(ManyLightSystems::Extract));
    match present {
        WebPresent::Canvas => {
            app.run();
        }
        WebPresent::ReadBack => run_read_back(app, canvas, webgl2)?,
    }
    Ok(())
}

/// Runs `app` (headless plugin) on the page's animation frames, drawing each frame that has
/// been read back into `canvas` through its 2D context. The device (WebGL2's when `webgl2`)
/// is requested first; the app updates once it has arrived and only while a read-back slot
/// is free.
fn run_read_back(mut app: App, canvas: web_sys::HtmlCanvasElement, webgl2: bool) -> Result<(), String> {
    let context = canvas
        .get_context("2d")
        .ok()
        .flatten()
        .and_then(|c| c.dyn_into::<web_sys::CanvasRenderingContext2d>().ok())
        .ok_or("the canvas has no 2D context")?;
    manylight::app::headless::finish_plugins(&mut app);
    // Headless rendering asks for its device with a blocking wait, which a page cannot make:
    // the app waits for the one requested below.
    app.insert_resource(RenderBackend::Pending);
    let frames_in_flight = app.world().resource::<manylight::app::FramesInFlight>().0;
    let app = Rc::new(RefCell::new(app));
    let display = DisplaySlot::default();
    {
        let (app, display) = (app.clone(), display.clone());
        wasm_bindgen_futures::spawn_local(async move {
            let sink: Result<Box<dyn FrameSink>, String> = if webgl2 {
                webgl2_sink(display).await
            } else {
                let instance = manylight::render::context::new_instance();
                GpuContext::request(instance, None).await.map_err(|e| e.to_string()).map(|gpu| {
                    let renderer = HeadlessRenderer::with_context(gpu, frames_in_flight);
                    Box::new(ReadBackSink::new(renderer, display)) as Box<dyn FrameSink>
                })
            };
            match sink {
                Ok(sink) => {
                    app.borrow_mut().insert_resource(RenderBackend::start(sink, false));
                }
                Err(message) => fail(&message),
            }
        });
    }
    // Each animation frame: update when the renderer can take a frame, then show the newest
    // frame that came back.
    let tick: FrameCallback = Rc::new(RefCell::new(None));
    let next = tick.clone();
    *tick.borrow_mut() = Some(Closure::new(move || {
        {
            let mut app = app.borrow_mut();
            if app.world().resource::<RenderBackend>().ready() && app.should_exit().is_none() {
                app.update();
            }
        }
        if let Some(image) = display.lock().ok().and_then(|mut slot| slot.take()) {
            show(&canvas, &context, &image);
        }
        if let Some(closure) = next.borrow().as_ref() {
            request_animation_frame(closure);
        }
    }));
    if let Some(closure) = tick.borrow().as_ref() {
        request_animation_frame(closure);
    }
    Ok(())
}

/// The WebGL2 sink: the texture-list renderer on a device of wgpu's GL backend, held to
/// WebGL2's limits. That backend finds its adapter through a canvas's `webgl2` context; the
/// page's canvas has the 2D context the frames are shown in, so the GL context gets a canvas
/// of its own, never shown (the frames are rendered offscreen).
async fn webgl2_sink(display: DisplaySlot) -> Result<Box<dyn FrameSink>, String> {
    let document = web_sys::window().and_then(|w| w.document()).ok_or("the window has no document")?;
    let gl_canvas = document
        .create_element("canvas")
        .ok()
        .and_then(|e| e.dyn_into::<web_sys::HtmlCanvasElement>().ok())
        .ok_or("cannot create a canvas for WebGL2")?;
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::GL;
    let instance = wgpu::Instance::new(desc);
    let surface = instance
        .create_surface(wgpu::SurfaceTarget::Canvas(gl_canvas))
        .map_err(|e| format!("WebGL2 is not available: {e}"))?;
    let gpu = GpuContext::request_webgl2(instance, Some(&surface)).await.map_err(|e| e.to_string())?;
    let renderer = TextureListRenderer::new(gpu).map_err(|e| e.to_string())?;
    Ok(Box::new(TextureListSink::new(renderer, Some(display)).keeping(surface)))
}

/// The animation-frame callback, which asks for the next frame with itself.
type FrameCallback = Rc<RefCell<Option<Closure<dyn FnMut()>>>>;

fn request_animation_frame(closure: &Closure<dyn FnMut()>) {
    if let Some(window) = web_sys::window() {
        let _ = window.request_animation_frame(closure.as_ref().unchecked_ref());
    }
}

/// Draws `image` into the 2D canvas at its own size.
fn show(
    canvas: &web_sys::HtmlCanvasElement,
    context: &web_sys::CanvasRenderingContext2d,
    image: &image::RgbaImage,
) {
    let (width, height) = image.dimensions();
    if canvas.width() != width || canvas.height() != height {
        canvas.set_width(width);
        canvas.set_height(height);
    }
    let pixels = wasm_bindgen::Clamped(image.as_raw().as_slice());
    match web_sys::ImageData::new_with_u8_clamped_array_and_sh(pixels, width, height) {
        Ok(data) => {
            let _ = context.put_image_data(&data, 0.0, 0.0);
        }
        Err(e) => fail(&format!("cannot show the frame: {e:?}")),
    }
}

/// Keeps [`INPUT`] up to date from the page's keyboard and mouse events (the canvas takes the
/// mouse; the keys are read wherever the page has focus).
fn listen_for_input(canvas: &web_sys::HtmlCanvasElement) -> Result<(), String> {
    let window = web_sys::window().ok_or("no window")?;
    let listen = |target: &web_sys::EventTarget, kind: &str, f: Closure<dyn FnMut(web_sys::Event)>| {
        let added = target.add_event_listener_with_callback(kind, f.as_ref().unchecked_ref());
        // The listeners live as long as the page.
        f.forget();
        added.map_err(|e| format!("cannot listen for {kind}: {e:?}"))
    };
    let key = |down: bool| {
        Closure::<dyn FnMut(web_sys::Event)>::new(move |e: web_sys::Event| {
            if let Some(e) = e.dyn_ref::<web_sys::KeyboardEvent>() {
                INPUT.with(|i| {
                    let mut i = i.borrow_mut();
                    i.shift = e.shift_key();
                    if down {
                        i.held.insert(e.code());
                    } else {
                        i.held.remove(&e.code());
                    }
                });
            }
        })
    };
    listen(&window, "keydown", key(true))?;
    listen(&window, "keyup", key(false))?;
    listen(
        &window,
        "blur",
        Closure::new(|_: web_sys::Event| INPUT.with(|i| *i.borrow_mut() = PointerKeys::default())),
    )?;
    listen(
        canvas,
        "mousedown",
        Closure::new(|_: web_sys::Event| INPUT.with(|i| i.borrow_mut().dragging = true)),
    )?;
    listen(
        &window,
        "mouseup",
        Closure::new(|_: web_sys::Event| INPUT.with(|i| i.borrow_mut().dragging = false)),
    )?;
    listen(
        &window,
        "mousemove",
        Closure::new(|e: web_sys::Event| {
            if let Some(e) = e.dyn_ref::<web_sys::MouseEvent>() {
                INPUT.with(|i| {
                    let mut i = i.borrow_mut();
                    if i.dragging {
                        i.drag += Vec2::new(e.movement_x() as f32, e.movement_y() as f32);
                    }
                });
            }
        }),
    )?;
    Ok(())
}

/// Moves the cameras by the input since the last update ([`crate::controls::fly`]).
fn fly_camera(time: Res<Time>, mut cameras: Query<&mut Transform, With<Camera3d>>) {
    let input = INPUT.with(|i| {
        let mut i = i.borrow_mut();
        let input = FlyInput {
            direction: FlyInput::direction_of(i.held.iter().map(String::as_str)),
            fast: i.shift,
            drag: i.drag,
        };
        i.drag = Vec2::ZERO;
        input
    });
    if input == FlyInput::default() {
        return;
    }
    for mut transform in &mut cameras {
        fly(&mut transform, &input, time.delta_secs());
    }
}

/// How the page shows its frames (the `present` parameter).
#[derive(Resource)]
struct Presenting(WebPresent);

/// The update whose image `capture()` returns (the `capture` parameter).
#[derive(Resource)]
struct CaptureAt(Option<u64>);

/// Asks for the image of the update named by [`CaptureAt`] (counted from 1), and only that one.
fn arm_capture(at: Res<CaptureAt>, mut capture: ResMut<HeadlessCapture>, mut updates: Local<u64>) {
    *updates += 1;
    capture.enabled = at.0 == Some(*updates);
}

/// Publishes the statistics, the ready title, the captured image and a failure to the page.
fn publish(
    stats: Res<FrameStats>,
    failure: Res<RenderFailure>,
    backend: Res<RenderBackend>,
    presenting: Res<Presenting>,
    mut capture: ResMut<HeadlessCapture>,
) {
    if let Some(message) = &failure.0 {
        let hint = if presenting.0 == WebPresent::Canvas && message.contains("lost") {
            " (a browser that cannot present a WebGPU canvas, such as headless Chromium on \
             SwiftShader, loses its device: add present=read-back to the URL)"
        } else {
            ""
        };
        fail(&format!("{message}{hint}"));
    }
    if let Some(image) = capture.image.take() {
        let mut png = Vec::new();
        match image.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png) {
            Ok(()) => {
                let url = format!(
                    "data:image/png;base64,{}",
                    base64::engine::general_purpose::STANDARD.encode(&png)
                );
                PAGE.with(|p| p.borrow_mut().capture = Some(url));
            }
            Err(e) => fail(&format!("cannot encode the captured image: {e}")),
        }
    }
    let Some(frame) = stats.last.as_ref().map(|r| r.frame_index) else {
        return;
    };
    if PAGE.with(|p| p.borrow().stats_frame) == Some(frame) {
        return;
    }
    let mut json = serde_json::to_value(stats.document()).unwrap_or(serde_json::Value::Null);
    json["backend"] =
        serde_json::Value::from(backend.adapter().map_or("unknown", |info| backend_name(info.backend)));
    let first = PAGE.with(|p| {
        let mut p = p.borrow_mut();
        let first = p.stats.is_none();
        p.stats = Some(json.to_string());
        p.stats_frame = Some(frame);
        first
    });
    if first && let Some(document) = web_sys::window().and_then(|w| w.document()) {
        document.set_title(READY_TITLE);
    }
}

/// The page contract's name of a wgpu backend.
fn backend_name(backend: manylight::render::wgpu::Backend) -> &'static str {
    match backend {
        manylight::render::wgpu::Backend::BrowserWebGpu => "webgpu",
        manylight::render::wgpu::Backend::Gl => "webgl2",
        other => other.to_str(),
    }
}
