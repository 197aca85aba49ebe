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

    /// The texture the graph writes (to read it back without waiting: [`PendingImage`]).
    pub fn texture(&self) -> &wgpu::Texture {
        &self.texture
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
    let (buffer, padded) = copy_to_buffer(gpu, texture, aspect, bytes_per_pixel);
    let row = width * bytes_per_pixel;
    let size = buffer.size();
    let bytes = read_buffer(gpu, &buffer, 0, size)?;
    let mut out = Vec::with_capacity((row * height) as usize);
    for y in 0..height as usize {
        let start = y * padded as usize;
        out.extend_from_slice(&bytes[start..start + row as usize]);
    }
    Ok(out)
}

/// A storage buffer of `bytes` a compute pass writes and [`dispatch_and_read`] reads back.
pub fn readback_output(gpu: &GpuContext, label: &str, bytes: u64) -> wgpu::Buffer {
    gpu.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

/// Runs the compute `pipeline` once per element of `count`, in workgroups of `workgroup`, with
/// `groups` bound at their indices, and reads back the first `bytes` of `output` (a measurement:
/// waits for the GPU).
pub fn dispatch_and_read(
    gpu: &GpuContext,
    label: &str,
    pipeline: &wgpu::ComputePipeline,
    groups: &[&wgpu::BindGroup],
    (count, workgroup): (u32, u32),
    output: &wgpu::Buffer,
    bytes: u64,
) -> Result<Vec<u8>, RenderError> {
    let mut encoder =
        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    {
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
        pass.set_pipeline(pipeline);
        for (index, group) in groups.iter().enumerate() {
            pass.set_bind_group(index as u32, *group, &[]);
        }
        pass.dispatch_workgroups(count.div_ceil(workgroup), 1, 1);
    }
    gpu.queue.submit([encoder.finish()]);
    read_buffer(gpu, output, 0, bytes)
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

/// Records and submits a copy of one aspect of `texture` into a new mappable buffer whose rows
/// are padded to wgpu's copy alignment; returns the buffer and its padded row bytes.
fn copy_to_buffer(
    gpu: &GpuContext,
    texture: &wgpu::Texture,
    aspect: wgpu::TextureAspect,
    bytes_per_pixel: u32,
) -> (wgpu::Buffer, u32) {
    let (width, height) = (texture.width(), texture.height());
    let row = width * bytes_per_pixel;
    let padded = row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = gpu.create_buffer(&wgpu::BufferDescriptor {
        label: Some("texture_readback"),
        size: padded as u64 * height as u64,
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
    (buffer, padded)
}

const MAP_PENDING: u8 = 0;
const MAP_DONE: u8 = 1;
const MAP_ERROR: u8 = 2;

/// An 8-bit RGBA or BGRA colour texture on its way to the CPU without a wait: the copy is
/// submitted and mapped when this is made, and [`PendingImage::try_take`] hands the image
/// over once the GPU has mapped it (in a browser, between two animation frames).
pub struct PendingImage {
    buffer: wgpu::Buffer,
    width: u32,
    height: u32,
    padded_row: u32,
    bgra: bool,
    state: std::sync::Arc<std::sync::atomic::AtomicU8>,
}

impl PendingImage {
    /// Starts copying `texture` (`Rgba8*` or `Bgra8*`, copyable) to the CPU.
    pub fn start(gpu: &GpuContext, texture: &wgpu::Texture) -> Result<PendingImage, RenderError> {
        use wgpu::TextureFormat as F;
        let format = texture.format();
        let bgra = matches!(format, F::Bgra8Unorm | F::Bgra8UnormSrgb);
        if !bgra && !matches!(format, F::Rgba8Unorm | F::Rgba8UnormSrgb) {
            return Err(RenderError::Readback(format!("{format:?} is not an 8-bit RGBA or BGRA format")));
        }
        let (buffer, padded_row) = copy_to_buffer(gpu, texture, wgpu::TextureAspect::All, 4);
        let state = std::sync::Arc::new(std::sync::atomic::AtomicU8::new(MAP_PENDING));
        let mapped = state.clone();
        buffer.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            mapped.store(if r.is_ok() { MAP_DONE } else { MAP_ERROR }, std::sync::atomic::Ordering::Release);
        });
        Ok(PendingImage { buffer, width: texture.width(), height: texture.height(), padded_row, bgra, state })
    }

    /// The image once the GPU has mapped the copy (`None` until then; polls without waiting).
    pub fn try_take(&self, gpu: &GpuContext) -> Option<Result<image::RgbaImage, RenderError>> {
        gpu.poll();
        match self.state.load(std::sync::atomic::Ordering::Acquire) {
            MAP_PENDING => None,
            MAP_ERROR => Some(Err(RenderError::Readback("mapping the image copy failed".into()))),
            _ => Some(self.unpack()),
        }
    }

    /// Takes the image out of `slot` once its copy has arrived: `None` while it is on its way
    /// or when the slot is empty; the slot is emptied when the image (or an error) comes back.
    pub fn take_arrived(
        slot: &mut Option<PendingImage>,
        gpu: &GpuContext,
    ) -> Result<Option<image::RgbaImage>, RenderError> {
        let taken = slot.as_ref().and_then(|p| p.try_take(gpu));
        if taken.is_some() {
            *slot = None;
        }
        taken.transpose()
    }

    fn unpack(&self) -> Result<image::RgbaImage, RenderError> {
        let row = (self.width * 4) as usize;
        let data = self.buffer.slice(..).get_mapped_range().map(|bytes| {
            let mut out = Vec::with_capacity(row * self.height as usize);
            for y in 0..self.height as usize {
                let start = y * self.padded_row as usize;
                out.extend_from_slice(&bytes[start..start + row]);
            }
            out
        });
        self.buffer.unmap();
        let mut pixels = data.map_err(|e| RenderError::Readback(e.to_string()))?;
        if self.bgra {
            for pixel in pixels.chunks_exact_mut(4) {
                pixel.swap(0, 2);
            }
        }
        image::RgbaImage::from_raw(self.width, self.height, pixels)
            .ok_or_else(|| RenderError::Readback("size mismatch".into()))
    }
}
