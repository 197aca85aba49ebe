//! Headless output: an sRGB texture the graph renders into, read back to an RGBA8 image.

use crate::context::{GpuContext, RenderError};

/// Format of the headless output.
pub const HEADLESS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// An offscreen render target with a readback path.
pub struct HeadlessTarget {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    width: u32,
    height: u32,
}

impl HeadlessTarget {
    /// Creates a `width × height` target (each at least 1).
    pub fn new(gpu: &GpuContext, width: u32, height: u32) -> HeadlessTarget {
        let (width, height) = (width.max(1), height.max(1));
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("headless_output"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: HEADLESS_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        HeadlessTarget { texture, view, width, height }
    }

    /// The view the graph writes as `OUTPUT`.
    pub fn view(&self) -> &wgpu::TextureView {
        &self.view
    }

    /// Size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Copies the target to the CPU (waits for the GPU).
    pub fn read(&self, gpu: &GpuContext) -> Result<image::RgbaImage, RenderError> {
        read_texture_rgba8(gpu, &self.texture, self.width, self.height)
    }
}

/// Reads a 4-bytes-per-pixel colour texture into an image (waits for the GPU).
pub fn read_texture_rgba8(
    gpu: &GpuContext,
    texture: &wgpu::Texture,
    width: u32,
    height: u32,
) -> Result<image::RgbaImage, RenderError> {
    let pixels = read_texture(gpu, texture, wgpu::TextureAspect::All, 4)?;
    image::RgbaImage::from_raw(width, height, pixels)
        .ok_or_else(|| RenderError::Readback("size mismatch".into()))
}

/// Copies one aspect of a texture (`bytes_per_pixel` per texel) to the CPU as tightly packed
/// rows (waits for the GPU).
pub fn read_texture(
    gpu: &GpuContext,
    texture: &wgpu::Texture,
    aspect: wgpu::TextureAspect,
    bytes_per_pixel: u32,
) -> Result<Vec<u8>, RenderError> {
    let (width, height) = (texture.width(), texture.height());
    let row = width * bytes_per_pixel;
    let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let size = padded as u64 * height as u64;
    let buffer = gpu.create_buffer(&wgpu::BufferDescriptor {
        label: Some("texture_readback"),
        size,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("texture_readback") });
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo { texture, mip_level: 0, origin: wgpu::Origin3d::ZERO, aspect },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([encoder.finish()]);
    let bytes = read_buffer(gpu, &buffer, 0, size)?;
    let mut out = Vec::with_capacity((row * height) as usize);
    for y in 0..height as usize {
        let start = y * padded as usize;
        out.extend_from_slice(&bytes[start..start + row as usize]);
    }
    Ok(out)
}

/// Copies `size` bytes of `buffer` from `offset` to the CPU (waits for the GPU).
pub fn read_buffer(
    gpu: &GpuContext,
    buffer: &wgpu::Buffer,
    offset: u64,
    size: u64,
) -> Result<Vec<u8>, RenderError> {
    let size = size.max(4).div_ceil(4) * 4;
    let staging_needed = !buffer.usage().contains(wgpu::BufferUsages::MAP_READ);
    // Refused here rather than left to a copy the device rejects, which reads back zeros.
    if offset.checked_add(size).is_none_or(|end| end > buffer.size()) {
        return Err(RenderError::Readback(format!(
            "{size} bytes at {offset} of a {}-byte buffer",
            buffer.size()
        )));
    }
    if staging_needed && !buffer.usage().contains(wgpu::BufferUsages::COPY_SRC) {
        return Err(RenderError::Readback("the buffer cannot be copied from (no COPY_SRC)".into()));
    }
    let staging;
    let (source, start) = if staging_needed {
        staging = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder =
            gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
        encoder.copy_buffer_to_buffer(buffer, offset, &staging, 0, size);
        gpu.queue.submit([encoder.finish()]);
        (&staging, 0)
    } else {
        (buffer, offset)
    };
    let slice = source.slice(start..start + size);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    gpu.wait_idle()?;
    rx.recv()
        .map_err(|e| RenderError::Readback(e.to_string()))?
        .map_err(|e| RenderError::Readback(e.to_string()))?;
    // Unmapped whatever the range gives, so a failed read leaves the buffer usable.
    let data = slice.get_mapped_range().map(|range| range.to_vec());
    source.unmap();
    data.map_err(|e| RenderError::Readback(e.to_string()))
}
