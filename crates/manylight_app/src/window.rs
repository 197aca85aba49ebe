//! The window: a winit event loop that drives the app, and a surface sink on the render thread
//! that survives resizes, minimising to 0×0 and lost or outdated surfaces.

use crate::backend::{FrameSink, RenderBackend, RenderThread};
use crate::render_world::{RenderWorld, empty_report};
use crate::resources::{RenderFailure, ViewportSize};
use bevy_app::{App, AppExit};
use glam::UVec2;
use manylight_render::{FrameReport, FrameSnapshot, GpuContext, RenderError};
use std::sync::Arc;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, KeyEvent, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

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
}

impl Default for WindowConfig {
    fn default() -> Self {
        Self { title: "manylight".into(), width: 1280, height: 720, vsync: true }
    }
}

/// Renders snapshots to a window surface.
pub struct SurfaceSink {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: Option<wgpu::SurfaceConfiguration>,
    render_world: RenderWorld,
    vsync: bool,
}

impl SurfaceSink {
    /// Creates the surface and a GPU context able to present to it.
    pub fn new(window: Arc<Window>, vsync: bool) -> Result<SurfaceSink, RenderError> {
        let instance = manylight_render::context::new_instance();
        let surface =
            instance.create_surface(window.clone()).map_err(|e| RenderError::Surface(e.to_string()))?;
        let gpu = GpuContext::with_instance(instance, Some(&surface))?;
        Ok(SurfaceSink { window, surface, config: None, render_world: RenderWorld::new(gpu), vsync })
    }

    fn configure(&mut self, size: UVec2) {
        let gpu = self.render_world.gpu();
        let caps = self.surface.get_capabilities(&gpu.adapter);
        let format = caps.formats.iter().copied().find(|f| f.is_srgb()).or(caps.formats.first().copied());
        let Some(format) = format else {
            tracing::error!("the surface supports no format");
            return;
        };
        let present_mode =
            if self.vsync { wgpu::PresentMode::AutoVsync } else { wgpu::PresentMode::AutoNoVsync };
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.x,
            height: size.y,
            present_mode,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        self.surface.configure(&gpu.device, &config);
        self.config = Some(config);
    }

    fn recreate_surface(&mut self) -> Result<(), RenderError> {
        let gpu = self.render_world.gpu();
        self.surface = gpu
            .instance
            .create_surface(self.window.clone())
            .map_err(|e| RenderError::Surface(e.to_string()))?;
        self.config = None;
        Ok(())
    }
}

impl FrameSink for SurfaceSink {
    fn render_frame(
        &mut self,
        snapshot: FrameSnapshot,
        _readback: bool,
    ) -> Result<(FrameReport, Option<image::RgbaImage>), RenderError> {
        let size = snapshot.viewport;
        if size.x == 0 || size.y == 0 {
            return Ok((empty_report(&snapshot), None)); // minimised: nothing to draw
        }
        if self.config.as_ref().map(|c| (c.width, c.height)) != Some((size.x, size.y)) {
            self.configure(size);
        }
        let Some(format) = self.config.as_ref().map(|c| c.format) else {
            return Ok((empty_report(&snapshot), None));
        };
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f) => f,
            wgpu::CurrentSurfaceTexture::Suboptimal(f) => {
                self.config = None; // reconfigure next frame
                f
            }
            wgpu::CurrentSurfaceTexture::Outdated => {
                self.config = None;
                return Ok((empty_report(&snapshot), None));
            }
            wgpu::CurrentSurfaceTexture::Lost => {
                tracing::warn!("surface lost: recreating it");
                self.recreate_surface()?;
                return Ok((empty_report(&snapshot), None));
            }
            other => {
                tracing::debug!("no surface texture this frame: {other:?}");
                return Ok((empty_report(&snapshot), None));
            }
        };
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
        let report = self.render_world.render(snapshot, &view, format)?;
        self.window.pre_present_notify();
        self.render_world.gpu().queue.present(frame);
        Ok((report, None))
    }
}

struct WinitRunner {
    app: App,
    config: WindowConfig,
    window: Option<Arc<Window>>,
    pipelined: bool,
    exit: Option<AppExit>,
}

impl WinitRunner {
    fn set_viewport(&mut self, size: winit::dpi::PhysicalSize<u32>) {
        self.app.world_mut().insert_resource(ViewportSize(UVec2::new(size.width, size.height)));
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, message: String) {
        tracing::error!("{message}");
        self.app.world_mut().insert_resource(RenderFailure(Some(message)));
        self.exit = Some(AppExit::error());
        event_loop.exit();
    }
}

impl ApplicationHandler for WinitRunner {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let attributes = Window::default_attributes().with_title(self.config.title.clone()).with_inner_size(
            winit::dpi::PhysicalSize::new(self.config.width.max(1), self.config.height.max(1)),
        );
        let window = match event_loop.create_window(attributes) {
            Ok(w) => Arc::new(w),
            Err(e) => return self.fail(event_loop, format!("could not open a window: {e}")),
        };
        let sink = match SurfaceSink::new(window.clone(), self.config.vsync) {
            Ok(s) => s,
            Err(e) => return self.fail(event_loop, e.to_string()),
        };
        let backend = if self.pipelined {
            match RenderThread::spawn(Box::new(sink)) {
                Ok(t) => RenderBackend::Pipelined(t),
                Err(e) => return self.fail(event_loop, format!("could not start the render thread: {e}")),
            }
        } else {
            RenderBackend::Sync { sink: Box::new(sink), pending: Vec::new() }
        };
        self.app.world_mut().insert_resource(backend);
        self.set_viewport(window.inner_size());
        window.request_redraw();
        self.window = Some(window);
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => {
                self.exit.get_or_insert(AppExit::Success);
                event_loop.exit();
            }
            WindowEvent::KeyboardInput {
                event:
                    KeyEvent { logical_key: Key::Named(NamedKey::Escape), state: ElementState::Pressed, .. },
                ..
            } => {
                self.exit.get_or_insert(AppExit::Success);
                event_loop.exit();
            }
            WindowEvent::Resized(size) => self.set_viewport(size),
            WindowEvent::RedrawRequested => {
                self.app.update();
                if let Some(exit) = self.app.should_exit() {
                    self.exit = Some(exit);
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }
}

/// Runs `app` in a window until it is closed, Esc is pressed or a system sends `AppExit`.
pub fn run_window(app: App, config: WindowConfig, pipelined: bool) -> AppExit {
    let event_loop = match EventLoop::new() {
        Ok(l) => l,
        Err(e) => {
            tracing::error!("could not start the window event loop (is a display available?): {e}");
            return AppExit::error();
        }
    };
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut runner = WinitRunner { app, config, window: None, pipelined, exit: None };
    if let Err(e) = event_loop.run_app(&mut runner) {
        tracing::error!("window event loop failed: {e}");
        return AppExit::error();
    }
    let exit = runner.exit.take().unwrap_or(AppExit::Success);
    // Dropping the app drops the render backend, which joins the render thread.
    drop(runner);
    exit
}
