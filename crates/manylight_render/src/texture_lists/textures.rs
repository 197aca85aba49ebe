//! The textures that carry the lights and their lists to the texture-list pass: each a fixed
//! width, as many rows as the frame needs, recreated taller when the data outgrows it.

use crate::context::{GpuContext, RenderError};

/// A 2D texture of `width`-texel rows of `format` (a 4-, 8- or 16-byte texel), written whole
/// each frame.
pub struct ListTexture {
    label: &'static str,
    format: wgpu::TextureFormat,
    width: u32,
    rows: u32,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
}

impl ListTexture {
    /// A one-row texture.
    pub fn new(
        gpu: &GpuContext,
        label: &'static str,
        format: wgpu::TextureFormat,
        width: u32,
    ) -> ListTexture {
        let (texture, view) = create(gpu, label, format, width, 1);
        ListTexture { label, format, width, rows: 1, texture, view }
    }

    /// Texels a row.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// The view the pass binds.
    pub fn view(&self) -> &wgpu::TextureView {
        &self.view
    }

    /// Writes `texels` (whole rows of [`ListTexture::width`]), growing the texture (to the
    /// next power of two of rows) when they do not fit; refused, naming the limit, past the
    /// device's largest texture. Returns true when the texture was recreated (its bind group
    /// must be made again).
    pub fn write(&mut self, gpu: &GpuContext, texels: &[u8]) -> Result<bool, RenderError> {
        let texel = self.format.block_copy_size(None).unwrap_or(4);
        let row_bytes = self.width * texel;
        let rows = (texels.len() as u32).div_ceil(row_bytes).max(1);
        let limit = gpu.max_texture_size();
        if rows > limit {
            return Err(RenderError::TextureTooLarge {
                label: self.label.to_string(),
                width: self.width,
                height: rows,
                limit,
            });
        }
        let grew = rows > self.rows;
        if grew {
            self.rows = rows.next_power_of_two().min(limit);
            (self.texture, self.view) = create(gpu, self.label, self.format, self.width, self.rows);
        }
        gpu.write_texture(
            self.texture.as_image_copy(),
            texels,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(row_bytes),
                rows_per_image: Some(rows),
            },
            wgpu::Extent3d { width: self.width, height: rows, depth_or_array_layers: 1 },
        );
        Ok(grew)
    }
}

fn create(
    gpu: &GpuContext,
    label: &'static str,
    format: wgpu::TextureFormat,
    width: u32,
    rows: u32,
) -> (wgpu::Texture, wgpu::TextureView) {
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height: rows, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    (texture, view)
}
