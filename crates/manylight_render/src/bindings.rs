//! Bind groups and small uniform buffers that outlive a frame, so that recording a pass in
//! steady state creates nothing: a pass asks for the bind group of a layout and its resources,
//! and gets the one it was given last time while those resources live; a pass's per-frame
//! constants go to a persistent uniform buffer, rewritten only when they change.
//!
//! A bind group holds its resources alive, so groups unused for [`KEEP_FRAMES`] frames (a
//! texture freed on a resize, a pass no longer in the plan) are dropped.

use crate::context::GpuContext;
use std::collections::HashMap;
use std::sync::Mutex;

/// Frames an unused bind group or uniform buffer is kept.
pub const KEEP_FRAMES: u64 = 3;

/// One resource of a bind group.
#[derive(Clone, Copy, Debug)]
pub enum Binding<'a> {
    /// A whole buffer.
    Buffer(&'a wgpu::Buffer),
    /// The first `size` bytes of a buffer (a shader's `arrayLength` sees only them).
    BufferPrefix(&'a wgpu::Buffer, wgpu::BufferSize),
    /// A texture view.
    Texture(&'a wgpu::TextureView),
    /// A sampler.
    Sampler(&'a wgpu::Sampler),
}

impl<'a> Binding<'a> {
    /// The resource of a bind group entry.
    pub fn resource(self) -> wgpu::BindingResource<'a> {
        match self {
            Binding::Buffer(x) => x.as_entire_binding(),
            Binding::BufferPrefix(buffer, size) => {
                wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer, offset: 0, size: Some(size) })
            }
            Binding::Texture(x) => wgpu::BindingResource::TextureView(x),
            Binding::Sampler(x) => wgpu::BindingResource::Sampler(x),
        }
    }
}

/// What identifies a bind group: its layout and resources (wgpu handles compare by identity).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Resource {
    Buffer(wgpu::Buffer),
    BufferPrefix(wgpu::Buffer, wgpu::BufferSize),
    Texture(wgpu::TextureView),
    Sampler(wgpu::Sampler),
}

/// A bind group's layout and resources by binding index.
type GroupKey = (wgpu::BindGroupLayout, Vec<(u32, Resource)>);

/// Key of a persistent uniform buffer: the type of the pass that owns it, the type of its
/// contents, and a number that tells a pass's uniforms of one type apart within a view (a
/// chain's level). Two passes never share a buffer, whatever they are called.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct UniformKey {
    /// The owning pass's type.
    pub pass: std::any::TypeId,
    /// The contents' type.
    pub contents: std::any::TypeId,
    /// Which of the pass's uniforms of that type.
    pub index: u64,
    /// The buffer's label: the contents' type name.
    pub label: &'static str,
}

struct Uniform {
    buffer: wgpu::Buffer,
    contents: Vec<u8>,
    used: u64,
}

/// The cache (in [`crate::graph::PassContext::bindings`]).
#[derive(Default)]
pub struct BindingCache {
    groups: Mutex<HashMap<GroupKey, (wgpu::BindGroup, u64)>>,
    uniforms: Mutex<HashMap<UniformKey, Uniform>>,
    frame: u64,
}

// wgpu handles hash and compare by the identity of the object they point to, which never
// changes; clippy sees the interior mutability behind the handle, not used by Hash or Eq.
#[allow(clippy::mutable_key_type)]
impl BindingCache {
    /// The bind group of `layout` with `bindings` (binding index, resource), created the
    /// first time these resources are bound together.
    pub fn bind_group(
        &self,
        gpu: &GpuContext,
        label: &'static str,
        layout: &wgpu::BindGroupLayout,
        bindings: &[(u32, Binding<'_>)],
    ) -> wgpu::BindGroup {
        let key: Vec<(u32, Resource)> = bindings
            .iter()
            .map(|&(i, b)| {
                let resource = match b {
                    Binding::Buffer(x) => Resource::Buffer(x.clone()),
                    Binding::BufferPrefix(x, size) => Resource::BufferPrefix(x.clone(), size),
                    Binding::Texture(x) => Resource::Texture(x.clone()),
                    Binding::Sampler(x) => Resource::Sampler(x.clone()),
                };
                (i, resource)
            })
            .collect();
        let mut groups = self.groups.lock().unwrap_or_else(|e| e.into_inner());
        let entry = groups.entry((layout.clone(), key)).or_insert_with(|| {
            let entries: Vec<wgpu::BindGroupEntry<'_>> = bindings
                .iter()
                .map(|&(binding, b)| wgpu::BindGroupEntry { binding, resource: b.resource() })
                .collect();
            let group = gpu.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &entries,
            });
            (group, self.frame)
        });
        entry.1 = self.frame;
        entry.0.clone()
    }

    /// The persistent uniform buffer `key`, holding `contents` (written only when they
    /// changed). Views of a frame are submitted one after the other, so each sees its own
    /// contents; within one view every uniform needs its own key.
    pub fn uniform(&self, gpu: &GpuContext, key: UniformKey, contents: &[u8]) -> wgpu::Buffer {
        let mut uniforms = self.uniforms.lock().unwrap_or_else(|e| e.into_inner());
        let create = || Uniform {
            buffer: gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some(key.label),
                size: (contents.len() as u64).max(16).next_multiple_of(16),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            contents: Vec::new(),
            used: self.frame,
        };
        let u = uniforms.entry(key).or_insert_with(create);
        if u.contents.len() != contents.len() && !u.contents.is_empty() {
            *u = create();
        }
        if u.contents != contents {
            gpu.write_buffer(&u.buffer, 0, contents);
            u.contents.clear();
            u.contents.extend_from_slice(contents);
        }
        u.used = self.frame;
        u.buffer.clone()
    }

    /// Starts a frame: drops what the last [`KEEP_FRAMES`] frames did not use.
    pub fn begin_frame(&mut self) {
        self.frame += 1;
        let frame = self.frame;
        let groups = self.groups.get_mut().unwrap_or_else(|e| e.into_inner());
        groups.retain(|_, (_, used)| frame - *used <= KEEP_FRAMES);
        let uniforms = self.uniforms.get_mut().unwrap_or_else(|e| e.into_inner());
        uniforms.retain(|_, u| frame - u.used <= KEEP_FRAMES);
    }
}
