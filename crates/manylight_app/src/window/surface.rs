//! The window surface on the render thread: configured on first use and on resize, skipped
//! while minimised (0×0) or larger than the device allows, reconfigured when outdated and
//! recreated when lost. When the app asks for read-back ([`crate::HeadlessCapture::enabled`]),
//! each frame's image is copied back before the overlay is drawn on it.

use super::overlay::OverlayPainter;
use crate::backend::FrameSink;
use crate::render_world::{DeviceSink, RenderWorld, SinkFrame, empty_report};
use glam::UVec2;
use manylight_render::{FrameReport, FrameSnapshot, GpuContext, RenderError};
use std::sync::Arc;
use winit::window::Window;

/// Renders snapshots to a window surface.
pub struct SurfaceSink {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: Option<wgpu::SurfaceConfiguration>,
    render_world: RenderWorld,
    vsync: bool,
    warned_too_large: bool,
    warned_readback: bool,
    overlay: Option<OverlayPainter>,
    /// A frame's image on its way to the CPU, where read-back cannot wait (a browser).
    pending_image: Option<manylight_render::readback::PendingImage>,
}

impl SurfaceSink {
    /// Creates the surface and a GPU context able to present to it; at most
    /// `frames_in_flight` frames are submitted and not yet read back. Blocks until the device
    /// arrives (native; a browser awaits [`SurfaceSink::request`]).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new(window: Arc<Window>, vsync: bool, frames_in_flight: u32) -> Result<SurfaceSink, RenderError> {
        pollster::block_on(Self::request(window, vsync, frames_in_flight))
    }

    /// Creates the surface, then requests a GPU context able to present to it; resolves when
    /// the device arrives.
    pub async fn request(
        window: Arc<Window>,
        vsync: bool,
        frames_in_flight: u32,
    ) -> Result<SurfaceSink, RenderError> {
        let instance = manylight_render::context::new_instance();
        let surface =
            instance.create_surface(window.clone()).map_err(|e| RenderError::Surface(e.to_string()))?;
        let gpu = GpuContext::request(instance, Some(&surface)).await?;
        Ok(SurfaceSink {
            window,
            surface,
            config: None,
            render_world: RenderWorld::with_frames_in_flight(gpu, frames_in_flight),
            vsync,
            warned_too_large: false,
            warned_readback: false,
            overlay: None,
            pending_image: None,
        })
    }

    /// Draws the egui overlay after each frame (its last pass, `egui_overlay`).
    pub(crate) fn with_overlay(mut self, painter: OverlayPainter) -> SurfaceSink {
        self.overlay = Some(painter);
        self
    }

    /// Configures the surface for `size` (both sides non-zero).
    fn configure(&mut self, size: UVec2) -> Result<(), RenderError> {
        let gpu = self.render_world.gpu();
        let caps = self.surface.get_capabilities(&gpu.adapter);
        let format = caps.formats.iter().copied().find(|f| f.is_srgb()).or(caps.formats.first().copied());
        let Some(format) = format else {
            return Err(RenderError::Surface(format!(
                "the window surface supports no format on adapter `{}`",
                gpu.info.name
            )));
        };
        let present_mode =
            if self.vsync { wgpu::PresentMode::AutoVsync } else { wgpu::PresentMode::AutoNoVsync };
        // Copies out of the swapchain serve read-back, where the surface allows them.
        // Copied from (read-back) and into (camera viewports) where the surface allows it.
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | (caps.usages & (wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST));
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            width: size.x,
            height: size.y,
            present_mode,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            // A surface without an sRGB format (a WebGPU canvas) is drawn through an sRGB view
            // of it, so the tone map's output is encoded as everywhere else.
            view_formats: if format.is_srgb() { vec![] } else { vec![format.add_srgb_suffix()] },
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        tracing::debug!("configuring the window surface: {}x{} {format:?}", size.x, size.y);
        self.surface.configure(&gpu.device, &config);
        self.config = Some(config);
        Ok(())
    }

    fn recreate_surface(&mut self) -> Result<(), RenderError> {
        let gpu = self.render_world.gpu();
        let surface = gpu
            .instance
            .create_surface(self.window.clone())
            .map_err(|e| RenderError::Surface(e.to_string()))?;
        self.surface = surface;
        self.config = None;
        Ok(())
    }

    /// The next surface texture at `size`, configuring or recreating the surface as needed.
    /// An outdated or lost surface is fixed and tried once more; `None` skips the frame.
    fn acquire(&mut self, size: UVec2) -> Result<Option<wgpu::SurfaceTexture>, RenderError> {
        for _attempt in 0..2 {
            if self.config.as_ref().map(|c| (c.width, c.height)) != Some((size.x, size.y)) {
                self.configure(size)?;
            }
            match self.surface.get_current_texture() {
                wgpu::CurrentSurfaceTexture::Success(frame) => return Ok(Some(frame)),
                wgpu::CurrentSurfaceTexture::Suboptimal(frame) => {
                    self.config = None; // configure again next frame
                    return Ok(Some(frame));
                }
                wgpu::CurrentSurfaceTexture::Outdated => {
                    tracing::debug!("surface outdated: configuring it again");
                    self.config = None;
                }
                wgpu::CurrentSurfaceTexture::Lost => {
                    tracing::warn!("surface lost: recreating it");
                    self.recreate_surface()?;
                }
                wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                    tracing::debug!("no surface texture this frame (timeout or occluded)");
                    return Ok(None);
                }
                wgpu::CurrentSurfaceTexture::Validation => {
                    // The error itself went to the device's error handler and fails the next
                    // frame with its message; configure from scratch in case that was the cause.
                    tracing::warn!("acquiring the surface texture raised a validation error");
                    self.config = None;
                    return Ok(None);
                }
            }
        }
        Ok(None)
    }

    /// Whether the surface can be read back: copyable and 8-bit RGBA or BGRA (one warning
    /// when it cannot).
    fn readable(&mut self, texture: &wgpu::Texture) -> bool {
        use wgpu::TextureFormat as F;
        let copyable = self.config.as_ref().is_some_and(|c| c.usage.contains(wgpu::TextureUsages::COPY_SRC));
        let format = texture.format();
        let readable = copyable
            && matches!(format, F::Bgra8Unorm | F::Bgra8UnormSrgb | F::Rgba8Unorm | F::Rgba8UnormSrgb);
        if !readable && !self.warned_readback {
            tracing::warn!("the window surface ({format:?}) cannot be read back: no images captured");
            self.warned_readback = true;
        }
        readable
    }

    /// Read-back without a wait: a frame asked to be read back starts a copy when none is on
    /// its way; the image comes back with the first later frame that finds the copy mapped
    /// (the frame asked for, not the one it comes back with).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    fn read_back_later(
        &mut self,
        texture: Option<&wgpu::Texture>,
    ) -> Result<Option<image::RgbaImage>, RenderError> {
        if self.pending_image.is_some() {
            let gpu = self.render_world.gpu();
            return manylight_render::readback::PendingImage::take_arrived(&mut self.pending_image, gpu);
        }
        if let Some(texture) = texture.filter(|t| self.readable(t)) {
            let gpu = self.render_world.gpu();
            self.pending_image = Some(manylight_render::readback::PendingImage::start(gpu, texture)?);
        }
        Ok(None)
    }

    /// The frame's image as RGBA8, when the surface can be copied from and is an 8-bit RGBA or
    /// BGRA format; `None` (with one warning) otherwise.
    #[cfg_attr(target_arch = "wasm32", allow(dead_code))]
    fn read_back(&mut self, texture: &wgpu::Texture) -> Result<Option<image::RgbaImage>, RenderError> {
        use wgpu::TextureFormat as F;
        if !self.readable(texture) {
            return Ok(None);
        }
        let gpu = self.render_world.gpu();
        let mut image =
            manylight_render::readback::read_texture_rgba8(gpu, texture, texture.width(), texture.height())?;
        if matches!(texture.format(), F::Bgra8Unorm | F::Bgra8UnormSrgb) {
            for pixel in image.pixels_mut() {
                pixel.0.swap(0, 2);
            }
        }
        Ok(Some(image))
    }
}

impl FrameSink for SurfaceSink {
    fn lose_device(&mut self, when: crate::render_world::DeviceLoss) {
        self.render_world.lose_device(when);
    }

    fn take_textures(&mut self) -> Vec<(manylight_render::RenderTextureId, image::RgbaImage)> {
        self.render_world.take_textures()
    }

    fn render_frame(&mut self, snapshot: FrameSnapshot, readback: bool) -> Result<SinkFrame, RenderError> {
        self.render_recovering(snapshot, readback)
    }

    fn set_stages(&mut self, stages: &std::sync::Arc<manylight_render::FramePlanner>) {
        self.render_world.set_stages(stages);
    }

    fn drain(&mut self) -> Result<Vec<FrameReport>, RenderError> {
        self.render_world.take_reports(true)
    }

    fn ready(&self) -> bool {
        self.render_world.renderer().can_begin_frame()
    }

    fn adapter(&self) -> Option<&wgpu::AdapterInfo> {
        Some(&self.render_world.gpu().info)
    }
}

impl DeviceSink for SurfaceSink {
    fn gpu(&self) -> &GpuContext {
        self.render_world.gpu()
    }

    fn render_world(&mut self) -> &mut RenderWorld {
        &mut self.render_world
    }

    /// A new surface for the window, a new render world on a device that can present to it,
    /// the overlay's GPU side rebuilt.
    fn recover(&mut self, reason: String, frame: u64) -> Result<(), RenderError> {
        // A surface texture acquired on the lost device cannot be released through it, and the
        // surface refuses to be configured again while it exists: start from a new surface.
        self.recreate_surface()?;
        self.render_world.recover_device(reason, frame, Some(&self.surface))?;
        self.config = None;
        if let Some(painter) = self.overlay.as_mut() {
            painter.reset_device();
        }
        Ok(())
    }

    fn render_on_device(
        &mut self,
        snapshot: FrameSnapshot,
        readback: bool,
    ) -> Result<(Option<FrameReport>, Option<image::RgbaImage>), RenderError> {
        let size = snapshot.viewport;
        if size.x == 0 || size.y == 0 {
            // Minimised: nothing to draw.
            return Ok((Some(self.render_world.report_empty(empty_report(&snapshot))), None));
        }
        let max = self.render_world.gpu().device.limits().max_texture_dimension_2d;
        if size.x > max || size.y > max {
            if !self.warned_too_large {
                tracing::warn!("window is {}x{}, larger than this GPU's {max}: not drawing", size.x, size.y);
                self.warned_too_large = true;
            }
            return Ok((Some(self.render_world.report_empty(empty_report(&snapshot))), None));
        }
        let Some(frame) = self.acquire(size)? else {
            return Ok((Some(self.render_world.report_empty(empty_report(&snapshot))), None));
        };
        let format = frame.texture.format().add_srgb_suffix();
        let view = frame
            .texture
            .create_view(&wgpu::TextureViewDescriptor { format: Some(format), ..Default::default() });
        let mut report = self.render_world.render(snapshot, &view, format)?;
        #[cfg(not(target_arch = "wasm32"))]
        let image = if readback { self.read_back(&frame.texture)? } else { None };
        #[cfg(target_arch = "wasm32")]
        let image = self.read_back_later(readback.then_some(&frame.texture))?;
        if let Some(painter) = self.overlay.as_mut() {
            let renderer = self.render_world.renderer_mut();
            if let Some((timing, timed)) =
                painter.paint(&renderer.gpu, &view, format, size, renderer.pass_timer())
            {
                renderer.pass_recorded(timed);
                report.passes.push(timing);
            }
        }
        self.render_world.finish_frame(report);
        self.window.pre_present_notify();
        self.render_world.gpu().queue.present(frame);
        Ok((None, image))
    }
}
