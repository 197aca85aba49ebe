//! The stages a frame is planned with: adding a pass means its module (with its `plan`
//! function), its WGSL file, and one line in [`STAGES`]; an app can also add a stage at run time
//! with [`FramePlanner::insert_after`].

use crate::graph::{Pass, RenderGraph};
use crate::passes;
use crate::plan::{PlanInputs, Planner};

/// The stages, in order: each pass module's `plan` function.
pub const STAGES: [(&str, Planner); 16] = [
    ("shadow_maps", passes::shadow_maps::plan),
    ("depth_prepass", passes::depth_prepass::plan),
    ("cluster_depth", passes::cluster_depth::plan),
    ("cluster_build", passes::cluster_build::plan),
    ("light_refine", passes::light_refine::plan),
    ("forward", passes::forward::plan),
    ("clustered_forward", passes::clustered_forward::plan),
    ("gbuffer", passes::gbuffer::plan),
    ("deferred_lighting", passes::deferred_lighting::plan),
    ("tiled_deferred", passes::tiled_deferred::plan),
    ("light_volumes", passes::light_volumes::plan),
    ("transparent", passes::transparent::plan),
    ("motion_blur", passes::motion_blur::plan),
    ("bloom", passes::bloom::plan),
    ("tonemap", passes::tonemap::plan),
    ("debug_view", passes::debug_view::plan),
];

/// The stages a frame is planned with.
#[derive(Clone, Debug)]
pub struct FramePlanner {
    stages: Vec<(&'static str, Planner)>,
}

impl Default for FramePlanner {
    fn default() -> Self {
        FramePlanner { stages: STAGES.to_vec() }
    }
}

impl FramePlanner {
    /// Adds stage `name` right after stage `after` (at the end when there is none of that
    /// name).
    pub fn insert_after(&mut self, after: &str, name: &'static str, planner: Planner) {
        let at = self.stages.iter().position(|(n, _)| *n == after).map_or(self.stages.len(), |i| i + 1);
        self.stages.insert(at, (name, planner));
    }

    /// The passes `inputs` call for, stage after stage.
    pub fn passes(&self, inputs: &PlanInputs<'_>) -> Vec<Box<dyn Pass>> {
        let mut out = Vec::new();
        for (_, planner) in &self.stages {
            planner(inputs, &mut out);
        }
        out
    }

    /// Fills `graph` with the passes `inputs` call for (it is cleared first).
    pub fn plan_into(&self, inputs: &PlanInputs<'_>, graph: &mut RenderGraph) {
        graph.clear();
        for pass in self.passes(inputs) {
            graph.add_boxed(pass);
        }
    }
}
