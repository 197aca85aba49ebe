//! Where views draw: render-to-texture targets (read back for the app), the images of view
//! rectangles (copied into their part of the target) and clearing what no view covers.

use super::CurrentView;
use manylight_render::{GpuContext, HeadlessTarget, RenderError, RenderTextureId, ViewTarget};
use std::collections::HashMap;

/// The render world's view targets, kept across frames.
#[derive(Default)]
pub(super) struct ViewTargets {
    /// Render-to-texture targets, by id (dropped when no view draws into them).
    textures: HashMap<RenderTextureId, HeadlessTarget>,
    /// Images of the view rectangles, copied into their targets, by size and format (only the
    /// sizes the last frame used are kept).
    view_images: HashMap<(u32, u32, wgpu::TextureFormat), wgpu::Texture>,
    /// The render-to-texture images of the last frame, until taken.
    pub(super) images: Vec<(RenderTextureId, image::RgbaImage)>,
}

impl ViewTargets {
    /// Keeps the targets `plans` draw into and frees the others: a render-to-texture target per
    /// id at its size (refused when it is empty or over the device's limit), and the
    /// view-rectangle images of this frame's sizes (a window being resized would otherwise
    /// leave one behind per size). `format`: the main target's.
    pub(super) fn keep_for(
        &mut self,
        gpu: &GpuContext,
        plans: &[ViewPlan],
        format: wgpu::TextureFormat,
    ) -> Result<(), RenderError> {
        self.textures.retain(|id, _| plans.iter().any(|p| p.texture_id() == Some(*id)));
        let limit = gpu.device.limits().max_texture_dimension_2d;
        for plan in plans {
            if let ViewTarget::Texture { id, size } = plan.target {
                if size.x > limit || size.y > limit {
                    return Err(RenderError::TargetTooLarge { width: size.x, height: size.y, limit });
                }
                if size.x == 0 || size.y == 0 {
                    return Err(RenderError::UnsupportedSettings(format!(
                        "a render image of {}×{} pixels (each side must be at least 1)",
                        size.x, size.y
                    )));
                }
                if self.textures.get(&id).map(|t| t.size()) != Some((size.x, size.y)) {
                    self.textures.insert(id, HeadlessTarget::new(gpu, size.x, size.y));
                }
            }
        }
        let format_of = |t: ViewTarget| match t {
            ViewTarget::Main => format,
            ViewTarget::Texture { .. } => manylight_render::HEADLESS_FORMAT,
        };
        self.view_images.retain(|&(w, h, f), _| {
            plans.iter().any(|p| {
                !p.whole && (p.view.view.size.x, p.view.view.size.y, format_of(p.target)) == (w, h, f)
            })
        });
        Ok(())
    }

    /// The view and format of `target`: `output` (of `format`) for the main target.
    pub(super) fn target_view(
        &self,
        target: ViewTarget,
        output: &wgpu::TextureView,
        format: wgpu::TextureFormat,
    ) -> (wgpu::TextureView, wgpu::TextureFormat) {
        match target {
            ViewTarget::Main => (output.clone(), format),
            ViewTarget::Texture { id, .. } => {
                (self.textures[&id].view().clone(), manylight_render::HEADLESS_FORMAT)
            }
        }
    }

    /// The image a view rectangle of `size` renders into before it is copied.
    pub(super) fn view_image(
        &mut self,
        gpu: &GpuContext,
        size: glam::UVec2,
        format: wgpu::TextureFormat,
    ) -> wgpu::Texture {
        self.view_images
            .entry((size.x, size.y, format))
            .or_insert_with(|| {
                gpu.device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("view_rect"),
                    size: wgpu::Extent3d { width: size.x, height: size.y, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                })
            })
            .clone()
    }

    /// Reads the render-to-texture targets back (the app asked for their pixels).
    pub(super) fn read(&mut self, gpu: &GpuContext) -> Result<(), RenderError> {
        let mut ids: Vec<_> = self.textures.keys().copied().collect();
        ids.sort();
        for id in ids {
            let image = self.textures[&id].read(gpu)?;
            self.images.push((id, image));
        }
        Ok(())
    }

    /// View-rectangle images alive.
    pub(super) fn view_image_count(&self) -> usize {
        self.view_images.len()
    }
}

/// What one view draws into.
pub(super) struct ViewPlan {
    /// The view.
    pub(super) view: CurrentView,
    /// Its target.
    pub(super) target: ViewTarget,
    /// Its rectangle of the target (`None`: a frame without views, drawing the whole target).
    pub(super) rect: Option<manylight_render::ViewRect>,
    /// True when it covers the whole target (it draws straight into it).
    pub(super) whole: bool,
    /// Its render order.
    pub(super) order: isize,
}

impl ViewPlan {
    fn texture_id(&self) -> Option<RenderTextureId> {
        match self.target {
            ViewTarget::Texture { id, .. } => Some(id),
            ViewTarget::Main => None,
        }
    }
}

/// `main`, or `texture N`.
pub(super) fn target_name(target: ViewTarget) -> String {
    match target {
        ViewTarget::Main => "main".to_string(),
        ViewTarget::Texture { id, .. } => format!("texture {}", id.0),
    }
}

/// Clears `target` to `color` (linear).
pub(super) fn clear_target(gpu: &GpuContext, target: &wgpu::TextureView, color: [f32; 3]) {
    let mut encoder =
        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("clear") });
    let [r, g, b] = color.map(f64::from);
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("clear_target"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    gpu.queue.submit([encoder.finish()]);
}

/// Copies a view's image into its rectangle of `target`.
pub(super) fn copy_into(
    gpu: &GpuContext,
    image: &wgpu::Texture,
    target: &wgpu::Texture,
    rect: manylight_render::ViewRect,
) -> Result<(), RenderError> {
    if !target.usage().contains(wgpu::TextureUsages::COPY_DST) {
        return Err(RenderError::UnsupportedSettings(
            "a camera viewport needs a target that can be copied into (COPY_DST), which this surface is not"
                .into(),
        ));
    }
    let mut encoder =
        gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("view_rect_copy") });
    encoder.copy_texture_to_texture(
        image.as_image_copy(),
        wgpu::TexelCopyTextureInfo {
            texture: target,
            mip_level: 0,
            origin: wgpu::Origin3d { x: rect.origin.x, y: rect.origin.y, z: 0 },
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::Extent3d { width: rect.size.x, height: rect.size.y, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([encoder.finish()]);
    Ok(())
}
