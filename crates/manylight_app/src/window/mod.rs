//! The window: a winit event loop that drives the app, and a surface sink on the render thread
//! that survives resizes, minimising to 0×0 and lost or outdated surfaces.
//!
//! How the runner goes about a frame:
//! 1. Window events update what the runner knows of the window: its inner size (`Resized`) and
//!    whether it is minimised (at the app's request, or reported as a 0×0 size).
//! 2. On `RedrawRequested` it publishes [`ViewportSize`] (0×0 while minimised), runs
//!    `App::update`, checks for `AppExit`, then applies the [`WindowRequests`] systems made.
//!    While the viewport is 0×0 the window may get no redraws at all, so the runner updates
//!    the app from a timer instead, about 60 times a second, and nothing is rendered.
//! 3. The extract system hands the snapshot to [`SurfaceSink`] (on the render thread when
//!    pipelined). The sink configures the surface to the snapshot's size; an outdated surface
//!    is configured again and a lost one recreated, and the frame is retried once.
//! 4. On exit, the runner waits for the frames in flight, records their results, drops the
//!    surface (joining the render thread) and only then the window.
//!
//! With [`WindowConfig::overlay`] the egui overlay ([`overlay`]) gets each window event first
//! and builds its UI before each update; the sink draws it after the frame.

pub mod overlay;
mod surface;
pub mod xvfb;

pub use overlay::{OVERLAY_PASS, Overlay};
pub use surface::SurfaceSink;

use crate::backend::RenderBackend;
use crate::resources::{RenderFailure, ViewportSize};
use bevy_app::{App, AppExit, PluginsState};
use bevy_ecs::prelude::*;
use glam::UVec2;
use std::sync::Arc;
use web_time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, KeyEvent, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// How often the app updates while the viewport is 0×0 (minimised): nothing is drawn then.
const IDLE_UPDATE_INTERVAL: Duration = Duration::from_millis(16);

/// Window parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct WindowConfig {
    /// Title bar text.
    pub title: String,
    /// Initial inner width in pixels.
    pub width: u32,
    /// Initial inner height in pixels.
    pub height: u32,
    /// Wait for vertical sync when presenting.
    pub vsync: bool,
    /// Allow the event loop on a thread other than the main one (X11, Wayland and Windows;
    /// ignored elsewhere). Off by default because macOS cannot do it; tests turn it on, since
    /// the test harness runs each test on a thread of its own.
    pub any_thread: bool,
    /// Show the egui overlay (settings and timings; F1 or the [`Overlay`] resource hides it).
    pub overlay: bool,
    /// In a browser: the canvas to draw into, sized by the page's CSS (`width` and `height`
    /// are then ignored). `None` appends a new canvas of `width × height` to the page's body.
    #[cfg(target_arch = "wasm32")]
    pub canvas: Option<web_sys::HtmlCanvasElement>,
}

impl Default for WindowConfig {
    fn default() -> Self {
        Self {
            title: "manylight".into(),
            width: 1280,
            height: 720,
            vsync: true,
            any_thread: false,
            overlay: true,
            #[cfg(target_arch = "wasm32")]
            canvas: None,
        }
    }
}

/// Keys pressed in the window since the last update, as logical keys: the character typed
/// (`"d"`, `"1"`) or the named key (`"ArrowRight"`, `"Space"`). Cleared after each update;
/// always empty headless.
#[derive(Resource, Clone, Debug, Default, PartialEq, Eq)]
pub struct PressedKeys(pub Vec<String>);

/// Changes to the window that systems ask for; the window runner applies them after each
/// update (the runner inserts this resource when it starts).
///
/// ```no_run
/// # use manylight_app::window::WindowRequests;
/// # use bevy_ecs::prelude::*;
/// fn shrink(mut requests: ResMut<WindowRequests>) {
///     requests.request_resize(glam::UVec2::new(640, 360));
/// }
/// ```
#[derive(Resource, Clone, Debug, Default, PartialEq, Eq)]
pub struct WindowRequests {
    resize: Option<UVec2>,
    minimize: Option<bool>,
    close: bool,
}

impl WindowRequests {
    /// Asks for a new inner size in physical pixels (each side at least 1; the last request of
    /// an update wins). The window system may adjust it: [`ViewportSize`] follows the size the
    /// window really gets.
    pub fn request_resize(&mut self, size: UVec2) {
        self.resize = Some(size.max(UVec2::ONE));
    }

    /// Asks to minimise (`true`) or restore (`false`) the window. From the next update until
    /// it is restored (by a request, or by the user where the window system reports it),
    /// [`ViewportSize`] is 0×0, nothing is rendered and the app updates about 60 times a second.
    pub fn request_minimize(&mut self, minimized: bool) {
        self.minimize = Some(minimized);
    }

    /// Asks to close the window: the app exits with `AppExit::Success` after this update.
    pub fn request_close(&mut self) {
        self.close = true;
    }

    /// True when nothing is asked for.
    pub fn is_empty(&self) -> bool {
        *self == WindowRequests::default()
    }
}

/// What reaches the event loop from outside a window event.
enum RunnerEvent {
    /// The window's renderer, once its device arrived (in a browser the device is requested
    /// asynchronously after the window exists).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    Renderer(Box<Result<SurfaceSink, manylight_render::RenderError>>),
}

/// The winit application: owns the app and the window, and turns window events into updates.
struct WinitRunner {
    /// Sends the renderer to the loop when its device arrives.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    proxy: winit::event_loop::EventLoopProxy<RunnerEvent>,
    app: App,
    config: WindowConfig,
    pipelined: bool,
    window: Option<Arc<Window>>,
    /// The inner size the window system last reported (0×0 when it minimises the window).
    window_size: UVec2,
    /// The app asked for the window to be minimised and has not seen it restored. The window
    /// system may not report minimising (X11 without a window manager ignores it), so this
    /// alone makes the viewport 0×0.
    minimize_requested: bool,
    /// The window system has reported the window hidden since the app asked to minimise it.
    seen_hidden: bool,
    next_idle_update: Instant,
    exit: Option<AppExit>,
    /// The egui overlay, when the config asks for it and the window exists.
    overlay: Option<overlay::OverlayHost>,
}

impl WinitRunner {
    /// The size the app renders at: 0×0 while minimised.
    fn viewport(&self) -> UVec2 {
        if self.minimize_requested { UVec2::ZERO } else { self.window_size }
    }

    fn idle(&self) -> bool {
        let v = self.viewport();
        v.x == 0 || v.y == 0
    }

    fn publish_viewport(&mut self) {
        let size = self.viewport();
        let world = self.app.world_mut();
        if world.get_resource::<ViewportSize>().map(|v| v.0) != Some(size) {
            world.insert_resource(ViewportSize(size));
        }
    }

    fn exit_with(&mut self, event_loop: &ActiveEventLoop, exit: AppExit) {
        self.exit.get_or_insert(exit);
        event_loop.exit();
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, message: String) {
        tracing::error!("{message}");
        self.app.world_mut().insert_resource(RenderFailure(Some(message)));
        self.exit_with(event_loop, AppExit::error());
    }

    /// One frame: update the app, then act on `AppExit` and on the window requests.
    fn update(&mut self, event_loop: &ActiveEventLoop) {
        if self.exit.is_some() {
            return;
        }
        // Without a render thread nothing may wait for the GPU: while the renderer is not
        // there yet or has no free frame slot, the app does not update (the next redraw asks
        // again).
        if !crate::backend::HAS_RENDER_THREAD
            && !self.app.world().get_resource::<RenderBackend>().is_some_and(RenderBackend::ready)
        {
            return;
        }
        self.publish_viewport();
        let idle = self.idle();
        if let (Some(host), Some(window)) = (self.overlay.as_mut(), self.window.as_ref())
            && !idle
        {
            host.run(window, self.app.world_mut());
        }
        let started = Instant::now();
        self.app.update();
        if let Some(host) = self.overlay.as_mut() {
            host.record_update(started.elapsed().as_secs_f64() * 1e3);
        }
        if let Some(mut keys) = self.app.world_mut().get_resource_mut::<PressedKeys>() {
            keys.0.clear();
        }
        if let Some(exit) = self.app.should_exit() {
            return self.exit_with(event_loop, exit);
        }
        self.apply_requests(event_loop);
    }

    fn apply_requests(&mut self, event_loop: &ActiveEventLoop) {
        let Some(window) = self.window.clone() else {
            return;
        };
        let requests = match self.app.world_mut().get_resource_mut::<WindowRequests>() {
            Some(mut r) if !r.is_empty() => std::mem::take(&mut *r),
            _ => return,
        };
        if requests.close {
            tracing::debug!("window close requested by the app");
            return self.exit_with(event_loop, AppExit::Success);
        }
        if let Some(size) = requests.resize {
            tracing::debug!("window resize to {}x{} requested by the app", size.x, size.y);
            if let Some(applied) = window.request_inner_size(PhysicalSize::new(size.x, size.y)) {
                self.window_size = UVec2::new(applied.width, applied.height);
            }
        }
        match requests.minimize {
            Some(true) => {
                tracing::debug!("window minimise requested by the app");
                window.set_minimized(true);
                self.minimize_requested = true;
                self.seen_hidden = false;
            }
            Some(false) => {
                tracing::debug!("window restore requested by the app");
                let hidden = self.minimize_requested
                    || window.is_minimized() == Some(true)
                    || self.window_size.min_element() == 0;
                if hidden {
                    // Only when hidden: on X11 restoring also activates (focuses) the window.
                    window.set_minimized(false);
                }
                self.minimize_requested = false;
            }
            None => {}
        }
    }

    /// While minimised at the app's request: notices the user restoring the window, where the
    /// window system says so.
    fn poll_restored(&mut self, window: &Window) {
        if !self.minimize_requested {
            return;
        }
        match window.is_minimized() {
            Some(true) => self.seen_hidden = true,
            Some(false) if self.seen_hidden => {
                tracing::debug!("window restored by the window system");
                self.minimize_requested = false;
            }
            _ => {}
        }
    }

    /// Waits for the frames in flight, records their results, then drops the surface (and the
    /// render thread) before the window goes.
    fn shut_down_renderer(&mut self) {
        let world = self.app.world_mut();
        let Some(mut backend) = world.remove_resource::<RenderBackend>() else {
            return;
        };
        let results = backend.flush();
        drop(backend);
        world.insert_resource(RenderBackend::Pending);
        if crate::backend::record_results(world, results) && self.exit.as_ref().is_none_or(|e| e.is_success())
        {
            self.exit = Some(AppExit::error());
        }
    }
}

impl WinitRunner {
    /// The window's attributes: title and size; in a browser, the canvas (the page's, or a new
    /// one appended to its body).
    fn window_attributes(&self) -> winit::window::WindowAttributes {
        let attributes = Window::default_attributes().with_title(self.config.title.clone());
        let sized = attributes
            .clone()
            .with_inner_size(PhysicalSize::new(self.config.width.max(1), self.config.height.max(1)));
        #[cfg(target_arch = "wasm32")]
        {
            use winit::platform::web::WindowAttributesExtWebSys;
            match self.config.canvas.clone() {
                Some(canvas) => attributes.with_canvas(Some(canvas)),
                None => sized.with_append(true),
            }
        }
        #[cfg(not(target_arch = "wasm32"))]
        {
            let _ = attributes;
            sized
        }
    }

    /// Starts drawing into `window` through `sink`: the overlay, the backend (pipelined when
    /// asked and possible), the first redraw.
    fn start_rendering(
        &mut self,
        event_loop: &ActiveEventLoop,
        sink: Result<SurfaceSink, manylight_render::RenderError>,
    ) {
        let Some(window) = self.window.clone() else {
            return;
        };
        let mut sink = match sink {
            Ok(s) => s,
            Err(e) => return self.fail(event_loop, e.to_string()),
        };
        if self.config.overlay {
            let (host, painter) = overlay::OverlayHost::new(&window);
            sink = sink.with_overlay(painter);
            self.overlay = Some(host);
            self.app.world_mut().init_resource::<Overlay>();
        }
        let backend = RenderBackend::start(Box::new(sink), self.pipelined);
        if let RenderBackend::Failed(message) = backend {
            return self.fail(event_loop, message);
        }
        self.app.world_mut().insert_resource(backend);
        let size = window.inner_size();
        self.window_size = UVec2::new(size.width, size.height);
        window.request_redraw();
    }

    fn frames_in_flight(&self) -> u32 {
        self.app
            .world()
            .get_resource::<crate::resources::FramesInFlight>()
            .map_or(manylight_render::DEFAULT_FRAMES_IN_FLIGHT, |f| f.0)
    }
}

impl ApplicationHandler<RunnerEvent> for WinitRunner {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() || self.exit.is_some() {
            return;
        }
        let window = match event_loop.create_window(self.window_attributes()) {
            Ok(w) => Arc::new(w),
            Err(e) => return self.fail(event_loop, format!("could not open a window: {e}")),
        };
        self.window = Some(window.clone());
        let (vsync, frames_in_flight) = (self.config.vsync, self.frames_in_flight());
        // A browser answers the device request asynchronously: the renderer arrives as a
        // `RunnerEvent` and the app updates from then on. Natively the request blocks here.
        #[cfg(target_arch = "wasm32")]
        {
            let _ = event_loop;
            let proxy = self.proxy.clone();
            wasm_bindgen_futures::spawn_local(async move {
                let sink = SurfaceSink::request(window, vsync, frames_in_flight).await;
                if proxy.send_event(RunnerEvent::Renderer(Box::new(sink))).is_err() {
                    tracing::debug!("the event loop ended before the GPU device arrived");
                }
            });
        }
        #[cfg(not(target_arch = "wasm32"))]
        self.start_rendering(event_loop, SurfaceSink::new(window, vsync, frames_in_flight));
    }

    fn user_event(&mut self, event_loop: &ActiveEventLoop, event: RunnerEvent) {
        match event {
            RunnerEvent::Renderer(sink) => self.start_rendering(event_loop, *sink),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if let WindowEvent::KeyboardInput {
            event: KeyEvent { logical_key: Key::Named(NamedKey::F1), state: ElementState::Pressed, .. },
            ..
        } = &event
            && let Some(mut overlay) = self.app.world_mut().get_resource_mut::<Overlay>()
        {
            overlay.visible = !overlay.visible;
            return;
        }
        // Input goes to the overlay first; what it uses does not reach the app.
        let overlay_visible = self.app.world().get_resource::<Overlay>().is_some_and(|o| o.visible);
        if let (Some(host), Some(window)) = (self.overlay.as_mut(), self.window.as_ref())
            && overlay_visible
            && host.on_window_event(window, &event)
            && matches!(event, WindowEvent::KeyboardInput { .. })
        {
            return;
        }
        match event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => {
                self.exit_with(event_loop, AppExit::Success);
            }
            // A page is closed by its tab, not by a key.
            WindowEvent::KeyboardInput {
                event:
                    KeyEvent { logical_key: Key::Named(NamedKey::Escape), state: ElementState::Pressed, .. },
                ..
            } if crate::backend::HAS_RENDER_THREAD => self.exit_with(event_loop, AppExit::Success),
            WindowEvent::KeyboardInput {
                event: KeyEvent { logical_key, state: ElementState::Pressed, .. },
                ..
            } => {
                if let Some(mut keys) = self.app.world_mut().get_resource_mut::<PressedKeys>() {
                    keys.0.push(match &logical_key {
                        Key::Character(c) => c.to_string(),
                        other => format!("{other:?}")
                            .trim_start_matches("Named(")
                            .trim_end_matches(')')
                            .to_string(),
                    });
                }
            }
            WindowEvent::Resized(size) => {
                tracing::trace!("window resized to {}x{}", size.width, size.height);
                self.window_size = UVec2::new(size.width, size.height);
            }
            WindowEvent::Focused(true) if self.minimize_requested => {
                // Focus comes back when the user restores the window. Trust it only where the
                // window system cannot say whether the window is minimised (Wayland) or has
                // said it was.
                let unknown = self.window.as_ref().is_some_and(|w| w.is_minimized().is_none());
                if unknown || self.seen_hidden {
                    tracing::debug!("window focused again: treating it as restored");
                    self.minimize_requested = false;
                }
            }
            // While idle the timer in `about_to_wait` drives updates.
            WindowEvent::RedrawRequested if !self.idle() => self.update(event_loop),
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.exit.is_some() {
            return;
        }
        let Some(window) = self.window.clone() else {
            return;
        };
        if self.idle() {
            self.poll_restored(&window);
            let now = Instant::now();
            if self.idle() && now >= self.next_idle_update {
                self.next_idle_update = now + IDLE_UPDATE_INTERVAL;
                self.update(event_loop);
            }
        }
        if self.exit.is_some() {
            return;
        }
        if self.idle() {
            event_loop.set_control_flow(ControlFlow::WaitUntil(self.next_idle_update));
        } else {
            event_loop.set_control_flow(ControlFlow::Poll);
            window.request_redraw();
        }
    }

    fn exiting(&mut self, _event_loop: &ActiveEventLoop) {
        self.shut_down_renderer();
        self.overlay = None;
        self.window = None;
    }
}

fn build_event_loop(config: &WindowConfig) -> Result<EventLoop<RunnerEvent>, winit::error::EventLoopError> {
    let mut builder = EventLoop::with_user_event();
    #[cfg(all(
        unix,
        not(any(target_os = "macos", target_os = "ios", target_os = "android", target_os = "emscripten"))
    ))]
    {
        // Sets the same flag for X11 and Wayland.
        use winit::platform::x11::EventLoopBuilderExtX11;
        builder.with_any_thread(config.any_thread);
    }
    #[cfg(windows)]
    {
        use winit::platform::windows::EventLoopBuilderExtWindows;
        builder.with_any_thread(config.any_thread);
    }
    #[cfg(not(any(
        windows,
        all(
            unix,
            not(any(
                target_os = "macos",
                target_os = "ios",
                target_os = "android",
                target_os = "emscripten"
            ))
        )
    )))]
    let _ = config;
    builder.build()
}

/// Runs `app` in a window until it is closed, Esc is pressed, a system sends `AppExit` or
/// calls [`WindowRequests::request_close`]. Returns the app's exit status (an error when
/// rendering failed, also in a frame that was still in flight at the close).
///
/// In a browser the event loop belongs to the page: this hands the app to it and returns at
/// once; the app runs on each animation frame, and a failure is recorded in
/// [`RenderFailure`] (the page reads it).
pub fn run_window(mut app: App, config: WindowConfig, pipelined: bool) -> AppExit {
    if app.plugins_state() != PluginsState::Cleaned {
        while app.plugins_state() == PluginsState::Adding {
            #[cfg(not(target_arch = "wasm32"))]
            std::thread::yield_now();
        }
        app.finish();
        app.cleanup();
    }
    app.init_resource::<WindowRequests>();
    let event_loop = match build_event_loop(&config) {
        Ok(l) => l,
        Err(e) => {
            tracing::error!("could not start the window event loop (is a display available?): {e}");
            return AppExit::error();
        }
    };
    event_loop.set_control_flow(ControlFlow::Poll);
    let size = UVec2::new(config.width, config.height);
    let runner = WinitRunner {
        proxy: event_loop.create_proxy(),
        app,
        config,
        pipelined,
        window: None,
        window_size: size,
        minimize_requested: false,
        seen_hidden: false,
        next_idle_update: Instant::now(),
        exit: None,
        overlay: None,
    };
    #[cfg(target_arch = "wasm32")]
    {
        use winit::platform::web::EventLoopExtWebSys;
        event_loop.spawn_app(runner);
        AppExit::Success
    }
    #[cfg(not(target_arch = "wasm32"))]
    run_to_exit(event_loop, runner)
}

/// Runs the event loop on this thread until the app exits.
#[cfg(not(target_arch = "wasm32"))]
fn run_to_exit(event_loop: EventLoop<RunnerEvent>, mut runner: WinitRunner) -> AppExit {
    let result = event_loop.run_app(&mut runner);
    // `exiting` has already stopped the renderer; this covers a loop that ended without it.
    runner.shut_down_renderer();
    runner.overlay = None;
    runner.window = None;
    if let Err(e) = result {
        tracing::error!("window event loop failed: {e}");
        return AppExit::error();
    }
    runner.exit.take().unwrap_or(AppExit::Success)
}
