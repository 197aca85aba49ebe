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

/// Why a stage could not be added.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum StageError {
    /// No stage has the name it was to follow.
    #[error("no stage `{after}` to add `{name}` after (stages: {known})")]
    UnknownStage {
        /// The name asked for.
        after: String,
        /// The stage that was to be added.
        name: &'static str,
        /// The stages there are, in order.
        known: String,
    },
    /// A stage of that name exists already.
    #[error("a stage `{0}` exists already")]
    Duplicate(&'static str),
}

impl FramePlanner {
    /// Adds stage `name` right after stage `after`; refused, naming the stages there are, when
    /// there is no stage `after`, or when a stage is called `name` already.
    pub fn insert_after(
        &mut self,
        after: &str,
        name: &'static str,
        planner: Planner,
    ) -> Result<(), StageError> {
        if self.stages.iter().any(|(n, _)| *n == name) {
            return Err(StageError::Duplicate(name));
        }
        let Some(i) = self.stages.iter().position(|(n, _)| *n == after) else {
            let known = self.stages.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ");
            return Err(StageError::UnknownStage { after: after.to_string(), name, known });
        };
        self.stages.insert(i + 1, (name, planner));
        Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;

    fn nothing(_: &PlanInputs<'_>, _: &mut Vec<Box<dyn Pass>>) {}

    #[test]
    fn a_stage_goes_after_a_known_one_and_never_silently_elsewhere() {
        let mut planner = FramePlanner::default();
        planner.insert_after("tonemap", "vignette", nothing).expect("tonemap is a stage");
        let names: Vec<&str> = planner.stages.iter().map(|(n, _)| *n).collect();
        let at = names.iter().position(|n| *n == "vignette").expect("added");
        assert_eq!(names[at - 1], "tonemap");
        let unknown = planner.insert_after("tone_map", "grain", nothing).unwrap_err();
        assert!(matches!(&unknown, StageError::UnknownStage { after, .. } if after == "tone_map"));
        assert!(unknown.to_string().contains("tonemap"), "{unknown}");
        assert_eq!(
            planner.insert_after("bloom", "vignette", nothing),
            Err(StageError::Duplicate("vignette"))
        );
        assert_eq!(planner.stages.len(), STAGES.len() + 1);
    }
}
