//! Transient textures, pooled by descriptor and reused across frames, and growable buffers.

use crate::context::{GpuContext, RenderError};

/// What a transient texture is: the pool's key.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureKey {
    /// Size in pixels.
    pub width: u32,
    /// Size in pixels.
    pub height: u32,
    /// Format.
    pub format: wgpu::TextureFormat,
    /// Usages.
    pub usage: wgpu::TextureUsages,
}

struct Entry {
    key: TextureKey,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    last_used: u64,
    in_use: bool,
}

impl Entry {
    fn bytes(&self) -> u64 {
        texel_bytes(self.key.format) * self.key.width as u64 * self.key.height as u64
    }
}

/// Frames a texture may stay unused before it is freed.
pub const TRANSIENT_KEEP_FRAMES: u64 = 3;

/// A pool of textures keyed by descriptor.
#[derive(Default)]
pub struct TransientPool {
    entries: Vec<Entry>,
    frame: u64,
    allocations: u64,
}

impl TransientPool {
    /// Starts a frame: every texture becomes available again; textures unused for more than
    /// [`TRANSIENT_KEEP_FRAMES`] frames are freed.
    pub fn begin_frame(&mut self) {
        self.frame += 1;
        let frame = self.frame;
        self.entries.retain(|e| frame - e.last_used <= TRANSIENT_KEEP_FRAMES);
        for e in &mut self.entries {
            e.in_use = false;
        }
    }

    /// Makes every texture available again within the frame (the next view of the frame runs
    /// after the last one finished).
    pub fn release_all(&mut self) {
        for e in &mut self.entries {
            e.in_use = false;
        }
    }

    /// A texture for `key` not yet handed out this frame, created if needed.
    pub fn acquire(&mut self, device: &wgpu::Device, key: TextureKey, label: &str) -> wgpu::TextureView {
        let frame = self.frame;
        if let Some(e) = self.entries.iter_mut().find(|e| e.key == key && !e.in_use) {
            e.in_use = true;
            e.last_used = frame;
            return e.view.clone();
        }
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: key.width.max(1),
                height: key.height.max(1),
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: key.format,
            usage: key.usage,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        self.allocations += 1;
        self.entries.push(Entry { key, texture, view: view.clone(), last_used: frame, in_use: true });
        view
    }

    /// Textures alive now.
    pub fn live(&self) -> usize {
        self.entries.len()
    }

    /// Bytes of the textures handed out this frame (texel size × pixels; drivers may pad or
    /// compress): what the frame's graph needs, whatever earlier frames left in the pool.
    pub fn frame_bytes(&self) -> u64 {
        self.entries.iter().filter(|e| e.last_used == self.frame).map(Entry::bytes).sum()
    }

    /// Textures created since start-up.
    pub fn allocations(&self) -> u64 {
        self.allocations
    }

    /// The textures handed out (for debugging).
    pub fn textures(&self) -> impl Iterator<Item = &wgpu::Texture> {
        self.entries.iter().map(|e| &e.texture)
    }
}

/// Bytes of one texel of `format` (the depth aspect for depth formats).
fn texel_bytes(format: wgpu::TextureFormat) -> u64 {
    format
        .block_copy_size(None)
        .or_else(|| format.block_copy_size(Some(wgpu::TextureAspect::DepthOnly)))
        .unwrap_or(4) as u64
}

/// Changed elements at most this many apart are written together by
/// [`GrowableBuffer::write_changed`] (a few unchanged bytes cost less than another write).
pub const MERGE_GAP: usize = 8;

/// A growable GPU buffer (storage or uniform) that is re-created larger when data outgrows it.
pub struct GrowableBuffer {
    label: &'static str,
    usage: wgpu::BufferUsages,
    buffer: wgpu::Buffer,
    capacity: u64,
    generation: u64,
    /// Largest size the device can bind (`max_storage_buffer_binding_size`, at most
    /// `max_buffer_size`).
    max_bytes: u64,
    /// The name of the limit `max_bytes` comes from.
    limit_name: &'static str,
}

impl GrowableBuffer {
    /// Creates a buffer of at least `min_bytes`.
    pub fn new(gpu: &GpuContext, label: &'static str, usage: wgpu::BufferUsages, min_bytes: u64) -> Self {
        let (max_bytes, limit_name) = crate::context::max_binding_bytes(&gpu.device.limits());
        // Powers of two keep regrowth rare; near the device's limit the buffer takes the limit.
        let capacity =
            min_bytes.max(16).next_power_of_two().min(max_bytes.max(16)).max(min_bytes.min(max_bytes));
        let buffer = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: capacity,
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self { label, usage, buffer, capacity, generation: 0, max_bytes, limit_name }
    }

    /// Uploads `data`, growing the buffer (to the next power of two) when it does not fit.
    /// Returns true when the buffer was re-created (bind groups that use it must be rebuilt).
    pub fn write(&mut self, gpu: &GpuContext, data: &[u8]) -> Result<bool, RenderError> {
        let grew = self.reserve(gpu, data.len() as u64)?;
        if !data.is_empty() {
            gpu.write_buffer(&self.buffer, 0, data);
        }
        Ok(grew)
    }

    /// Uploads `data` where it differs from `previous` (what the buffer holds; `None` when that
    /// is not known): `data` is compared `element` bytes at a time and each run of changed
    /// elements is one write (runs fewer than [`MERGE_GAP`] elements apart are merged). Writes
    /// everything when `previous` is unknown or the buffer had to be re-created. Returns the
    /// bytes written (0 when nothing changed).
    pub fn write_changed(
        &mut self,
        gpu: &GpuContext,
        data: &[u8],
        previous: Option<&[u8]>,
        element: usize,
    ) -> Result<u64, RenderError> {
        let grew = self.reserve(gpu, data.len() as u64)?;
        let element = element.max(1);
        // Partial writes need offsets that are multiples of `COPY_BUFFER_ALIGNMENT` (4).
        let Some(previous) = previous.filter(|_| !grew && element.is_multiple_of(4)) else {
            if !data.is_empty() {
                gpu.write_buffer(&self.buffer, 0, data);
            }
            return Ok(data.len() as u64);
        };
        if previous.get(..data.len()) == Some(data) {
            return Ok(0);
        }
        let bytes =
            |range: std::ops::Range<usize>| range.start * element..(range.end * element).min(data.len());
        let same =
            |range: std::ops::Range<usize>| previous.get(bytes(range.clone())) == data.get(bytes(range));
        let mut written = 0;
        let mut write = |run: std::ops::Range<usize>| {
            let range = bytes(run);
            written += range.len() as u64;
            gpu.write_buffer(&self.buffer, range.start as u64, &data[range]);
        };
        // Blocks of elements are compared at once (one memcmp each), then the elements of a
        // block that differs one by one.
        const BLOCK: usize = 64;
        let count = data.len().div_ceil(element);
        let changed = (0..count.div_ceil(BLOCK))
            .map(|b| b * BLOCK..((b + 1) * BLOCK).min(count))
            .filter(|block| !same(block.clone()))
            .flat_map(|block| block.filter(|&i| !same(i..i + 1)));
        let mut run: Option<std::ops::Range<usize>> = None;
        for i in changed {
            run = match run {
                Some(r) if i - r.end < MERGE_GAP => Some(r.start..i + 1),
                Some(r) => {
                    write(r);
                    Some(i..i + 1)
                }
                None => Some(i..i + 1),
            };
        }
        if let Some(r) = run {
            write(r);
        }
        Ok(written)
    }

    /// Makes room for `bytes`; returns true when the buffer was re-created.
    /// Refused, naming the limit, when `bytes` exceed what the device can bind.
    pub fn reserve(&mut self, gpu: &GpuContext, bytes: u64) -> Result<bool, RenderError> {
        if bytes <= self.capacity {
            return Ok(false);
        }
        if bytes > self.max_bytes {
            return Err(RenderError::BufferTooLarge {
                label: self.label.to_string(),
                bytes,
                limit: self.max_bytes,
                limit_name: self.limit_name,
            });
        }
        *self = GrowableBuffer {
            generation: self.generation + 1,
            ..Self::new(gpu, self.label, self.usage, bytes)
        };
        Ok(true)
    }

    /// Re-creates the buffer smaller when it holds more than four times `bytes` (rounded up to
    /// a power of two as it grows): what a few frames needed (a count made before a frame had
    /// its depth bounds, a burst of lights) is not held for good. Returns true when it did (the
    /// contents are gone; bind groups that use it must be rebuilt).
    pub fn shrink_to(&mut self, gpu: &GpuContext, bytes: u64) -> bool {
        let wanted = bytes.max(16).next_power_of_two();
        if self.capacity <= wanted.saturating_mul(4) {
            return false;
        }
        *self = GrowableBuffer {
            generation: self.generation + 1,
            ..Self::new(gpu, self.label, self.usage, wanted)
        };
        true
    }

    /// The most bytes the device can bind.
    pub fn max_bytes(&self) -> u64 {
        self.max_bytes
    }

    /// The buffer.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// Capacity in bytes.
    pub fn capacity(&self) -> u64 {
        self.capacity
    }

    /// Incremented each time the buffer is re-created.
    pub fn generation(&self) -> u64 {
        self.generation
    }
}
