//! Bind groups declared once. Each bind group a shader reads is a [`BindGroupDecl`]: its
//! bindings, each with its number, WGSL variable name, kind and the stages that see it. The
//! layout a pipeline is made with ([`GroupLayout`]) and every bind group made for that layout
//! come from the declaration, so a binding number is written in Rust only there.
//! [`SHADER_BIND_GROUPS`] says which declaration each entry point of each shader reads at each
//! group: the pipeline helpers of [`crate::passes::common`] check the layouts they are given
//! against it, and `tests/shaders.rs` checks every `@group`/`@binding` of the WGSL against it
//! with naga (no GPU).
//!
//! An app's pass declares its own group the same way and makes its pipeline with
//! [`crate::passes::common::fullscreen_pipeline_with_module`].

use crate::bindings::Binding;
use crate::context::{BindingError, GpuContext};
use crate::shaders::ShaderDefs;
use crate::snapshot::GBufferLayout;

mod groups;

pub use groups::*;

/// What a binding holds, as its WGSL declaration says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    /// `var<uniform>`.
    Uniform,
    /// `var<storage, read>` (`read_only`) or `var<storage, read_write>`.
    Storage {
        /// `read` rather than `read_write`.
        read_only: bool,
    },
    /// A 2D texture: `texture_2d<f32>` (filterable or not), `texture_2d<u32>` or
    /// `texture_depth_2d`.
    Texture(wgpu::TextureSampleType),
    /// A cube texture, `texture_cube<f32>`.
    Cube(wgpu::TextureSampleType),
    /// A write-only 2D storage texture, `texture_storage_2d<format, write>`.
    StorageTexture(wgpu::TextureFormat),
    /// A write-only array of 2D storage textures, `texture_storage_2d_array<format, write>`
    /// (the six faces of one mip level of a cube).
    StorageTextureArray(wgpu::TextureFormat),
    /// `sampler` (filtering or not) or `sampler_comparison`.
    Sampler(wgpu::SamplerBindingType),
}

impl BindingKind {
    /// The layout entry's binding type.
    pub fn binding_type(self) -> wgpu::BindingType {
        let buffer = |ty| wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None };
        match self {
            BindingKind::Uniform => buffer(wgpu::BufferBindingType::Uniform),
            BindingKind::Storage { read_only } => buffer(wgpu::BufferBindingType::Storage { read_only }),
            BindingKind::Texture(sample_type) => wgpu::BindingType::Texture {
                sample_type,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            BindingKind::Cube(sample_type) => wgpu::BindingType::Texture {
                sample_type,
                view_dimension: wgpu::TextureViewDimension::Cube,
                multisampled: false,
            },
            BindingKind::StorageTexture(format) => wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            BindingKind::StorageTextureArray(format) => wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format,
                view_dimension: wgpu::TextureViewDimension::D2Array,
            },
            BindingKind::Sampler(ty) => wgpu::BindingType::Sampler(ty),
        }
    }
}

/// The compositions of a shader in which a binding exists: its WGSL declaration sits under
/// this define (`//!if`), so the layout holds it only then.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Presence {
    /// In every composition.
    Always,
    /// With `SHADOWS` ([`ShaderDefs::shadows`]).
    Shadows,
    /// With `ENVIRONMENT` ([`ShaderDefs::environment`]).
    Environment,
    /// With `RAYS` ([`ShaderDefs::rays`]).
    Rays,
    /// With this G-buffer layout ([`ShaderDefs::gbuffer`]).
    GBuffer(GBufferLayout),
}

impl Presence {
    /// Whether a shader composed with `defs` declares the binding.
    pub fn holds(self, defs: ShaderDefs) -> bool {
        match self {
            Presence::Always => true,
            Presence::Shadows => defs.shadows,
            Presence::Environment => defs.environment,
            Presence::Rays => defs.rays,
            Presence::GBuffer(layout) => defs.gbuffer == Some(layout),
        }
    }
}

/// One binding of a bind group, as its WGSL declares it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BindingDecl {
    /// `@binding(n)`.
    pub binding: u32,
    /// The WGSL variable.
    pub name: &'static str,
    /// What it holds.
    pub kind: BindingKind,
    /// The stages whose entry points may read it.
    pub visibility: wgpu::ShaderStages,
    /// The compositions that declare it.
    pub presence: Presence,
}

impl BindingDecl {
    /// A binding of `kind`, present in every composition.
    pub const fn new(
        binding: u32,
        name: &'static str,
        kind: BindingKind,
        visibility: wgpu::ShaderStages,
    ) -> BindingDecl {
        BindingDecl { binding, name, kind, visibility, presence: Presence::Always }
    }

    /// A `var<uniform>`.
    pub const fn uniform(binding: u32, name: &'static str, visibility: wgpu::ShaderStages) -> BindingDecl {
        BindingDecl::new(binding, name, BindingKind::Uniform, visibility)
    }

    /// A `var<storage, read>`.
    pub const fn storage(binding: u32, name: &'static str, visibility: wgpu::ShaderStages) -> BindingDecl {
        BindingDecl::new(binding, name, BindingKind::Storage { read_only: true }, visibility)
    }

    /// A `var<storage, read_write>`.
    pub const fn storage_rw(binding: u32, name: &'static str, visibility: wgpu::ShaderStages) -> BindingDecl {
        BindingDecl::new(binding, name, BindingKind::Storage { read_only: false }, visibility)
    }

    /// A 2D texture of `sample_type`.
    pub const fn texture(
        binding: u32,
        name: &'static str,
        sample_type: wgpu::TextureSampleType,
        visibility: wgpu::ShaderStages,
    ) -> BindingDecl {
        BindingDecl::new(binding, name, BindingKind::Texture(sample_type), visibility)
    }

    /// This binding, declared only in the compositions `presence` names.
    pub const fn only(self, presence: Presence) -> BindingDecl {
        BindingDecl { presence, ..self }
    }

    /// The layout entry.
    pub fn layout_entry(&self) -> wgpu::BindGroupLayoutEntry {
        wgpu::BindGroupLayoutEntry {
            binding: self.binding,
            visibility: self.visibility,
            ty: self.kind.binding_type(),
            count: None,
        }
    }
}

/// Stages of a binding read by fragment shaders and by compute shaders that shade the same way
/// (tiled deferred, the passes that read the G-buffer).
pub const SHADING: wgpu::ShaderStages = wgpu::ShaderStages::FRAGMENT.union(wgpu::ShaderStages::COMPUTE);
/// A float texture read with `textureLoad` (no filtering).
pub const UNFILTERED: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: false };

/// A bind group: its bindings, as the WGSL declares them.
#[derive(Debug, PartialEq, Eq)]
pub struct BindGroupDecl {
    /// The label of its layout and groups; unique among the declarations.
    pub label: &'static str,
    /// Its group number (`@group(index)` in the WGSL): the same in every pipeline that binds
    /// it (checked against [`SHADER_BIND_GROUPS`]), so passes bind it with
    /// `set_bind_group(DECL.index, …)`, never a bare number.
    pub index: u32,
    /// Its bindings.
    pub entries: &'static [BindingDecl],
}

impl BindGroupDecl {
    /// The bindings a shader composed with `defs` declares, in declaration order.
    pub fn entries_for(&'static self, defs: ShaderDefs) -> impl Iterator<Item = &'static BindingDecl> {
        self.entries.iter().filter(move |e| e.presence.holds(defs))
    }

    /// The layout of this group for shaders composed with `defs`.
    pub fn create_layout(&'static self, device: &wgpu::Device, defs: ShaderDefs) -> GroupLayout {
        let entries: Vec<BindingDecl> = self.entries_for(defs).copied().collect();
        let layout_entries: Vec<wgpu::BindGroupLayoutEntry> =
            entries.iter().map(|e| e.layout_entry()).collect();
        let raw = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(self.label),
            entries: &layout_entries,
        });
        GroupLayout { decl: self, entries, raw }
    }
}

/// A bind group layout made from its [`BindGroupDecl`] for one composition of the shaders.
/// Its bind groups take one resource per binding, in the declaration's order.
#[derive(Clone, Debug)]
pub struct GroupLayout {
    decl: &'static BindGroupDecl,
    entries: Vec<BindingDecl>,
    raw: wgpu::BindGroupLayout,
}

impl GroupLayout {
    /// Its declaration.
    pub fn decl(&self) -> &'static BindGroupDecl {
        self.decl
    }

    /// The bindings it holds, in declaration order.
    pub fn entries(&self) -> &[BindingDecl] {
        &self.entries
    }

    /// The wgpu layout.
    pub fn raw(&self) -> &wgpu::BindGroupLayout {
        &self.raw
    }

    /// `resources` (one per binding, in declaration order) with their binding numbers. A
    /// resource missing, extra or of another kind than declared is left for wgpu's validation
    /// of the bind group to report (a [`crate::RenderError::Device`] of the frame).
    pub fn numbered<'a>(&self, resources: &[Binding<'a>]) -> Vec<(u32, Binding<'a>)> {
        let numbers = self.entries.iter().map(|e| e.binding).chain(self.entries.len() as u32..);
        numbers.zip(resources.iter().copied()).collect()
    }

    /// A new bind group of `resources` (one per binding, in declaration order), for groups that
    /// live longer than the frame's cache keeps them.
    pub fn create_bind_group(&self, gpu: &GpuContext, resources: &[Binding<'_>]) -> wgpu::BindGroup {
        let numbered = self.numbered(resources);
        let entries: Vec<wgpu::BindGroupEntry<'_>> = numbered
            .iter()
            .map(|&(binding, resource)| wgpu::BindGroupEntry { binding, resource: resource.resource() })
            .collect();
        gpu.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.decl.label),
            layout: &self.raw,
            entries: &entries,
        })
    }
}

/// The bind groups that entry points of a library shader read, group 0 first.
#[derive(Debug)]
pub struct ShaderBindGroups {
    /// The shader file under `shaders/`.
    pub shader: &'static str,
    /// The entry points these groups serve; empty: every entry point of the shader.
    pub entry_points: &'static [&'static str],
    /// The declaration of each group, group 0 first.
    pub groups: &'static [&'static BindGroupDecl],
}

impl ShaderBindGroups {
    /// Whether this row covers `entry_point` of `shader`.
    pub fn covers(&self, shader: &str, entry_point: &str) -> bool {
        self.shader == shader && (self.entry_points.is_empty() || self.entry_points.contains(&entry_point))
    }
}

/// The row of [`SHADER_BIND_GROUPS`] that covers every one of `entry_points` of `shader`: the
/// entry points of one pipeline.
pub fn shader_bind_groups(shader: &str, entry_points: &[&str]) -> Option<&'static ShaderBindGroups> {
    SHADER_BIND_GROUPS
        .iter()
        .find(|row| row.shader == shader && entry_points.iter().all(|e| row.covers(shader, e)))
}

/// Checks that a pipeline of `shader`'s `entry_points` is made with the layouts their row of
/// [`SHADER_BIND_GROUPS`] declares, group by group.
pub fn check_pipeline(
    shader: &str,
    entry_points: &[&str],
    layouts: &[&GroupLayout],
) -> Result<(), BindingError> {
    let entry_point = || entry_points.join("+");
    let row = shader_bind_groups(shader, entry_points)
        .ok_or_else(|| BindingError::Undeclared { shader: shader.to_owned(), entry_point: entry_point() })?;
    for group in 0..row.groups.len().max(layouts.len()) {
        let declared = row.groups.get(group).map(|d| d.label);
        let given = layouts.get(group).map(|l| l.decl.label);
        if declared != given {
            return Err(BindingError::Pipeline {
                shader: shader.to_owned(),
                entry_point: entry_point(),
                group,
                declared: declared.unwrap_or("none"),
                given: given.unwrap_or("none"),
            });
        }
    }
    Ok(())
}

/// The pipeline layout of bind groups `layouts`, group 0 first.
pub fn pipeline_layout(device: &wgpu::Device, label: &str, layouts: &[&GroupLayout]) -> wgpu::PipelineLayout {
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|l| Some(l.raw())).collect();
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    })
}

/// The compute pipeline of `shader`'s `entry` over the bind groups `layouts` (group 0 first),
/// with its `override` constants (`label` names the layout and the pipeline).
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    shader: &str,
    layouts: &[&GroupLayout],
    entry: &str,
    constants: &[(&str, f64)],
) -> Result<wgpu::ComputePipeline, crate::context::RenderError> {
    compute_pipeline_with_defs(device, label, shader, layouts, entry, constants, Default::default())
}

/// [`compute_pipeline`] with its shader composed with `defs`.
pub fn compute_pipeline_with_defs(
    device: &wgpu::Device,
    label: &str,
    shader: &str,
    layouts: &[&GroupLayout],
    entry: &str,
    constants: &[(&str, f64)],
    defs: crate::shaders::ShaderDefs,
) -> Result<wgpu::ComputePipeline, crate::context::RenderError> {
    check_pipeline(shader, &[entry], layouts)?;
    let module = crate::shaders::create_module_with(device, shader, defs)?;
    let layout = pipeline_layout(device, label, layouts);
    Ok(device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&layout),
        module: &module,
        entry_point: Some(entry),
        compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
        cache: None,
    }))
}
