//! The render graph: passes declare what they read and write; the graph orders them, drops
//! the ones whose outputs nobody reads, and lists what it built.
//!
//! Building a frame happens in three steps:
//! 1. systems add passes ([`RenderGraph::add`]) for the effects the frame calls for;
//! 2. [`RenderGraph::compile`] keeps the passes that contribute to [`OUTPUT`] and orders them
//!    so that every reader comes after the writers of what it reads (ties keep insertion order);
//! 3. [`crate::renderer::Renderer::execute`] allocates transient textures from its pool,
//!    records each pass inside timestamp queries, and submits without waiting (the figures
//!    arrive later: [`crate::inflight`]).

use crate::context::{GpuContext, RenderError};
use crate::pipelines::PipelineCache;
use crate::resources::SceneResources;
use std::collections::HashMap;

/// A graph resource's declaration: its label (snake_case; also its texture's label). Each
/// declaration is one resource, whatever its label: declare one with [`resource!`](crate::resource!).
#[derive(Debug)]
pub struct GraphResource {
    label: &'static str,
}

impl GraphResource {
    /// A declaration labelled `label`; its address is the resource's identity, so it must be
    /// a `static` ([`resource!`](crate::resource!) makes one).
    pub const fn new(label: &'static str) -> GraphResource {
        GraphResource { label }
    }
}

/// A graph resource (a texture or buffer slot): passes say what they read and write with these
/// handles, declared once with [`resource!`](crate::resource!) (`passes::HDR`, `passes::DEPTH`, …). A handle is
/// its declaration, not its label: two declarations with the same label are two resources.
#[derive(Clone, Copy)]
pub struct ResourceName(&'static GraphResource);

impl ResourceName {
    /// The resource declared by `declaration` (a `static`; see [`resource!`](crate::resource!)).
    pub const fn of(declaration: &'static GraphResource) -> ResourceName {
        ResourceName(declaration)
    }

    /// Its label (for texture labels and messages).
    pub const fn name(self) -> &'static str {
        self.0.label
    }
}

impl PartialEq for ResourceName {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.0, other.0)
    }
}

impl Eq for ResourceName {}

impl std::hash::Hash for ResourceName {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        std::ptr::hash(self.0, state);
    }
}

impl PartialOrd for ResourceName {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for ResourceName {
    /// By label, then by declaration (two declarations of one label stay apart).
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        let address = |r: &ResourceName| r.0 as *const GraphResource as usize;
        self.name().cmp(other.name()).then_with(|| address(self).cmp(&address(other)))
    }
}

impl std::fmt::Debug for ResourceName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ResourceName({})", self.name())
    }
}

impl std::fmt::Display for ResourceName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Declares a graph resource labelled `$label`: a [`ResourceName`] of its own, unequal to every
/// other declaration's (each expansion makes one `static`).
///
/// ```
/// use manylight_render::{ResourceName, resource};
/// const BLURRED: ResourceName = resource!("blurred");
/// const ALSO_BLURRED: ResourceName = resource!("blurred");
/// assert_ne!(BLURRED, ALSO_BLURRED);
/// assert_eq!(BLURRED.name(), "blurred");
/// ```
#[macro_export]
macro_rules! resource {
    ($label:literal) => {{
        static DECLARATION: $crate::graph::GraphResource = $crate::graph::GraphResource::new($label);
        $crate::graph::ResourceName::of(&DECLARATION)
    }};
}

/// The external resource every frame ends in: the swapchain image or the headless target.
pub const OUTPUT: ResourceName = crate::resource!("output");

/// The HDR scene colour (`passes::HDR`): the shading passes create it, the post passes filter
/// it, the tone map reads it.
pub const HDR: ResourceName = crate::resource!("hdr");

/// The second HDR image, which a post-processing pass writes into while it reads [`HDR`]
/// ([`PassContext::post_process_write`] swaps the two; `passes::HDR_SWAP`).
pub const HDR_SWAP: ResourceName = crate::resource!("hdr_swap");

/// A transient texture a pass creates: sized relative to the viewport.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureSpec {
    /// Resource name.
    pub name: ResourceName,
    /// Format.
    pub format: wgpu::TextureFormat,
    /// Usages.
    pub usage: wgpu::TextureUsages,
    /// Size as a fraction of the viewport (1.0 = full resolution).
    pub scale: f32,
}

/// One pass of the graph.
pub trait Pass: std::any::Any + Send + Sync {
    /// Name, also the wgpu label (snake_case).
    fn name(&self) -> &'static str;
    /// Resources read.
    fn reads(&self) -> Vec<ResourceName>;
    /// Resources written.
    fn writes(&self) -> Vec<ResourceName>;
    /// Transient textures this pass creates (it must also list them in `writes`).
    fn creates(&self) -> Vec<TextureSpec> {
        Vec::new()
    }
    /// True for compute passes (their GPU timings are flagged as untrusted on CPU adapters).
    fn is_compute(&self) -> bool {
        false
    }
    /// Records the pass.
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError>;
}

/// A pass whose name is known from its type: code that reads a frame's timings (the benchmark
/// CLI, tests) finds the pass by type ([`crate::FrameReport::pass`]) instead of by a copied
/// string. Every built-in pass has one; its [`Pass::name`] returns [`NamedPass::NAME`].
pub trait NamedPass: Pass {
    /// What [`Pass::name`] returns.
    const NAME: &'static str;
}

/// True when `pass` is a `P`: the renderer asks a plan for a pass by its type, not its name.
pub fn is<P: Pass>(pass: &dyn Pass) -> bool {
    (pass as &dyn std::any::Any).is::<P>()
}

/// What a pass sees while it records.
pub struct PassContext<'a> {
    /// Device and queue.
    pub gpu: &'a GpuContext,
    /// The frame's uploaded scene data (view, lights, meshes, materials).
    pub scene: &'a SceneResources,
    /// Pipelines, created on first use.
    pub pipelines: &'a PipelineCache,
    /// Cluster buffers, when the frame uses clusters.
    pub clusters: Option<&'a crate::clusters::ClusterResources>,
    /// The shadow atlas and its pass's buffers (`None` outside a renderer).
    pub shadows: Option<&'a crate::shadows::ShadowResources>,
    /// The prefiltered environments (`None` outside a renderer).
    pub environments: Option<&'a crate::environment::EnvironmentMaps>,
    /// Bind groups and uniform buffers kept across frames (record creates none in steady
    /// state).
    pub bindings: &'a crate::bindings::BindingCache,
    /// The frame's command encoder.
    pub encoder: &'a mut wgpu::CommandEncoder,
    /// Format of [`OUTPUT`].
    pub output_format: wgpu::TextureFormat,
    pub(crate) textures: &'a HashMap<ResourceName, wgpu::TextureView>,
    /// True once a post-processing pass swapped the HDR image into [`HDR_SWAP`] (the view's
    /// passes share it: [`PassContext::post_process_write`]).
    pub(crate) hdr_swapped: &'a std::cell::Cell<bool>,
    pub(crate) timer: Option<&'a wgpu::QuerySet>,
    pub(crate) pass_index: u32,
    pub(crate) stamps: (bool, bool),
    /// The type of the pass recording (the owner of its uniforms).
    pub(crate) pass_type: std::any::TypeId,
}

impl<'a> PassContext<'a> {
    /// The frame's cluster buffers, which pass `pass` needs: an error naming it when the frame
    /// has none (the plan added the pass without the clusters it reads).
    pub fn require_clusters(&self, pass: &str) -> Result<&'a crate::clusters::ClusterResources, RenderError> {
        self.clusters.ok_or_else(|| RenderError::Graph(format!("{pass} needs cluster resources")))
    }

    /// The bind group of `layout` with `resources` (one per binding, in the order its
    /// [`crate::layouts::BindGroupDecl`] declares them), kept by the frame's
    /// [`crate::bindings::BindingCache`] while they live.
    pub fn bind_group(
        &self,
        layout: &crate::layouts::GroupLayout,
        resources: &[crate::bindings::Binding<'_>],
    ) -> wgpu::BindGroup {
        let numbered = layout.numbered(resources);
        self.bindings.bind_group(self.gpu, layout.decl().label, layout.raw(), &numbered)
    }

    /// A persistent uniform buffer holding `value`, the recording pass's one of type `T`
    /// ([`crate::bindings::BindingCache::uniform`]; rewritten only when `value` changes).
    pub fn uniform<T: bytemuck::Pod>(&self, value: &T) -> wgpu::Buffer {
        self.uniform_at(0, value)
    }

    /// The recording pass's uniform `index` of type `T` holding `value`, for a pass that binds
    /// several (a chain's levels).
    pub fn uniform_at<T: bytemuck::Pod>(&self, index: u64, value: &T) -> wgpu::Buffer {
        let key = crate::bindings::UniformKey {
            pass: self.pass_type,
            contents: std::any::TypeId::of::<T>(),
            index,
            label: std::any::type_name::<T>(),
        };
        self.bindings.uniform(self.gpu, key, bytemuck::bytes_of(value))
    }

    /// The view of a graph texture (transient or [`OUTPUT`]). [`HDR`] is the HDR image as the
    /// passes before left it, wherever [`PassContext::post_process_write`] put it.
    pub fn texture(&self, name: ResourceName) -> Result<&'a wgpu::TextureView, RenderError> {
        let swapped = self.hdr_swapped.get();
        let name = if swapped && name == HDR {
            HDR_SWAP
        } else if swapped && name == HDR_SWAP {
            HDR
        } else {
            name
        };
        self.textures
            .get(&name)
            .ok_or_else(|| RenderError::Graph(format!("texture `{name}` was not allocated")))
    }

    /// For a pass that filters the HDR image (Bevy's `post_process_write`): the image to read
    /// (`source`) and a texture of the same size and format to write the result into
    /// (`destination`), which the passes after this one see as [`HDR`]. The pass reads and
    /// writes `HDR` and creates `passes::post_process_texture()`; it must write every pixel of
    /// `destination` (a full-screen draw does).
    pub fn post_process_write(&self) -> Result<PostProcessWrite<'a>, RenderError> {
        let source = self.texture(HDR)?;
        let destination = self.texture(HDR_SWAP).map_err(|_| {
            RenderError::Graph(
                "post_process_write: the pass does not create `passes::post_process_texture()`".into(),
            )
        })?;
        self.hdr_swapped.set(!self.hdr_swapped.get());
        Ok(PostProcessWrite { source, destination })
    }

    /// Timestamp writes for a render pass; `first`/`last` say whether this wgpu pass opens or
    /// closes the graph pass (a graph pass may record several wgpu passes).
    pub fn render_timestamps(
        &mut self,
        first: bool,
        last: bool,
    ) -> Option<wgpu::RenderPassTimestampWrites<'a>> {
        let qs = self.timer?;
        self.stamps.0 |= first;
        self.stamps.1 |= last;
        Some(wgpu::RenderPassTimestampWrites {
            query_set: qs,
            beginning_of_pass_write_index: first.then_some(self.pass_index * 2),
            end_of_pass_write_index: last.then_some(self.pass_index * 2 + 1),
        })
    }

    /// Timestamp writes for a compute pass (see [`Self::render_timestamps`]).
    pub fn compute_timestamps(
        &mut self,
        first: bool,
        last: bool,
    ) -> Option<wgpu::ComputePassTimestampWrites<'a>> {
        let qs = self.timer?;
        self.stamps.0 |= first;
        self.stamps.1 |= last;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: qs,
            beginning_of_pass_write_index: first.then_some(self.pass_index * 2),
            end_of_pass_write_index: last.then_some(self.pass_index * 2 + 1),
        })
    }
}

/// Where a post-processing pass reads and writes the HDR image
/// ([`PassContext::post_process_write`]).
#[derive(Clone, Copy, Debug)]
pub struct PostProcessWrite<'a> {
    /// The HDR image as the passes before left it.
    pub source: &'a wgpu::TextureView,
    /// Where the pass writes the image; the HDR image of the passes after it.
    pub destination: &'a wgpu::TextureView,
}

/// What the order of a graph depends on: each pass's name, reads and writes.
type Signature = Vec<(&'static str, Vec<ResourceName>, Vec<ResourceName>)>;

/// Compiled orders kept (one per distinct plan seen lately; the oldest is dropped).
const KEPT_ORDERS: usize = 16;

/// The passes of one frame. The graph is refilled for every view, but compiled only when the
/// plan changes: the order of each distinct plan (its passes' names, reads and writes) is kept.
#[derive(Default)]
pub struct RenderGraph {
    passes: Vec<Box<dyn Pass>>,
    orders: std::sync::Mutex<Vec<(Signature, Vec<usize>)>>,
    compilations: std::sync::atomic::AtomicU64,
}

impl RenderGraph {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a pass.
    pub fn add(&mut self, pass: impl Pass + 'static) {
        self.passes.push(Box::new(pass));
    }

    /// Adds a pass that is already boxed (e.g. one of a list a settings type builds).
    pub fn add_boxed(&mut self, pass: Box<dyn Pass>) {
        self.passes.push(pass);
    }

    /// Removes every pass (the graph is refilled for each view; compiled orders are kept).
    pub fn clear(&mut self) {
        self.passes.clear();
    }

    /// Times a plan was compiled (ordered from scratch) since the graph was created: it grows
    /// only when a view's plan changes.
    pub fn compilations(&self) -> u64 {
        self.compilations.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Names of the passes as added (before culling).
    pub fn added_names(&self) -> Vec<&'static str> {
        self.passes.iter().map(|p| p.name()).collect()
    }

    /// Names of the passes that will run, in order.
    pub fn pass_names(&self) -> Result<Vec<&'static str>, RenderError> {
        Ok(self.compile()?.into_iter().map(|i| self.passes[i].name()).collect())
    }

    /// The pass at `index` (as returned by [`Self::compile`]).
    pub fn pass(&self, index: usize) -> &dyn Pass {
        self.passes[index].as_ref()
    }

    /// Indices of the passes that contribute to [`OUTPUT`], in execution order: the kept
    /// order when this plan was compiled before.
    pub fn compile(&self) -> Result<Vec<usize>, RenderError> {
        let signature: Signature = self.passes.iter().map(|p| (p.name(), p.reads(), p.writes())).collect();
        let mut orders = self.orders.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, order)) = orders.iter().find(|(s, _)| *s == signature) {
            return Ok(order.clone());
        }
        let order = self.order()?;
        self.compilations.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if orders.len() >= KEPT_ORDERS {
            orders.remove(0);
        }
        orders.push((signature, order.clone()));
        Ok(order)
    }

    /// Orders the passes from scratch (see [`RenderGraph::compile`]).
    fn order(&self) -> Result<Vec<usize>, RenderError> {
        let n = self.passes.len();
        let reads: Vec<Vec<ResourceName>> = self.passes.iter().map(|p| p.reads()).collect();
        let writes: Vec<Vec<ResourceName>> = self.passes.iter().map(|p| p.writes()).collect();
        // Dependencies: for each resource a pass reads, the other passes that write it earlier
        // in insertion order, or, when there are none, every other writer (a system may add a
        // consumer before its producer). A pass that only writes a resource starts it afresh
        // and depends on nothing for it.
        let mut deps: Vec<Vec<usize>> = vec![Vec::new(); n];
        for i in 0..n {
            for r in &reads[i] {
                let writers: Vec<usize> = (0..n).filter(|&j| j != i && writes[j].contains(r)).collect();
                let earlier: Vec<usize> = writers.iter().copied().filter(|&j| j < i).collect();
                if !earlier.is_empty() {
                    deps[i].extend(earlier);
                } else if !writers.is_empty() {
                    deps[i].extend(writers);
                } else if !writes[i].contains(r) {
                    return Err(RenderError::Graph(format!(
                        "pass `{}` reads `{r}` but no pass writes it",
                        self.passes[i].name()
                    )));
                }
            }
        }
        // Live passes: those writing OUTPUT and, transitively, what they depend on.
        let mut live = vec![false; n];
        let mut stack: Vec<usize> = (0..n).filter(|&i| writes[i].contains(&OUTPUT)).collect();
        while let Some(i) = stack.pop() {
            if !std::mem::replace(&mut live[i], true) {
                stack.extend(deps[i].iter().copied());
            }
        }
        // Topological order (Kahn), lowest insertion index first among the ready ones.
        let mut order = Vec::new();
        let mut done = vec![false; n];
        let live_count = live.iter().filter(|&&l| l).count();
        while order.len() < live_count {
            let next = (0..n).find(|&i| live[i] && !done[i] && deps[i].iter().all(|&d| done[d] || !live[d]));
            match next {
                Some(i) => {
                    done[i] = true;
                    order.push(i);
                }
                None => return Err(RenderError::Graph("the passes' reads and writes form a cycle".into())),
            }
        }
        Ok(order)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_declarations_with_one_label_are_two_resources() {
        const A: ResourceName = crate::resource!("scratch");
        const B: ResourceName = crate::resource!("scratch");
        assert_eq!(A, A);
        assert_ne!(A, B);
        assert_eq!(A.name(), B.name());
        let set: std::collections::HashSet<ResourceName> = [A, B, A].into_iter().collect();
        assert_eq!(set.len(), 2);
    }

    struct Fake(&'static str, Vec<ResourceName>, Vec<ResourceName>);
    impl Pass for Fake {
        fn name(&self) -> &'static str {
            self.0
        }
        fn reads(&self) -> Vec<ResourceName> {
            self.1.clone()
        }
        fn writes(&self) -> Vec<ResourceName> {
            self.2.clone()
        }
        fn record(&self, _: &mut PassContext<'_>) -> Result<(), RenderError> {
            Ok(())
        }
    }

    #[test]
    fn orders_by_dependencies_and_drops_unread_passes() {
        let mut g = RenderGraph::new();
        g.add(Fake("tonemap", vec![HDR], vec![OUTPUT]));
        g.add(Fake("unused", vec![], vec![crate::resource!("scratch")]));
        g.add(Fake("bloom", vec![HDR], vec![HDR]));
        g.add(Fake("forward", vec![], vec![HDR, crate::resource!("depth")]));
        assert_eq!(g.pass_names().unwrap(), vec!["forward", "bloom", "tonemap"]);
    }

    #[test]
    fn missing_writer_is_an_error() {
        let mut g = RenderGraph::new();
        g.add(Fake("tonemap", vec![HDR], vec![OUTPUT]));
        assert!(matches!(g.compile(), Err(RenderError::Graph(_))));
    }

    #[test]
    fn a_plan_is_compiled_once_until_it_changes() {
        let mut g = RenderGraph::new();
        let fill = |g: &mut RenderGraph, bloom: bool| {
            g.clear();
            g.add(Fake("forward", vec![], vec![HDR]));
            if bloom {
                g.add(Fake("bloom", vec![HDR], vec![HDR]));
            }
            g.add(Fake("tonemap", vec![HDR], vec![OUTPUT]));
        };
        fill(&mut g, false);
        assert_eq!(g.pass_names().unwrap(), vec!["forward", "tonemap"]);
        fill(&mut g, false);
        assert_eq!(g.pass_names().unwrap(), vec!["forward", "tonemap"]);
        assert_eq!(g.compilations(), 1);
        fill(&mut g, true);
        assert_eq!(g.pass_names().unwrap(), vec!["forward", "bloom", "tonemap"]);
        fill(&mut g, false);
        g.compile().unwrap();
        assert_eq!(g.compilations(), 2, "both plans are kept");
    }

    #[test]
    fn empty_graph_runs_nothing() {
        assert!(RenderGraph::new().pass_names().unwrap().is_empty());
    }
}
