//! The stages a frame is planned with. A stage is a `plan` function (it adds its pass when the
//! view calls for it) named by the type of the pass it adds ([`StageId`]): adding a built-in
//! pass means its module (with its `plan` function), its WGSL file and one line in
//! [`builtin_stages`]; an app adds its own stage before or after any other one by type
//! ([`FramePlanner::insert_before`], [`FramePlanner::insert_after`]).

use crate::graph::{Pass, RenderGraph};
use crate::passes;
use crate::plan::{PlanInputs, Planner};
use std::any::TypeId;

/// Which stage: the type of the pass it adds (of the first pass, for bloom's chain), so a stage
/// is placed and found by type, never by a string.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct StageId {
    type_id: TypeId,
    name: &'static str,
}

impl StageId {
    /// The stage whose pass is a `P`.
    pub fn of<P: Pass>() -> StageId {
        // The type's name from its last path segment on, generic arguments whole
        // (`Probe<1>`, `Blur<my_app::Wide>`).
        let full = std::any::type_name::<P>();
        let path = &full[..full.find('<').unwrap_or(full.len())];
        let name = &full[path.rfind("::").map_or(0, |i| i + 2)..];
        StageId { type_id: TypeId::of::<P>(), name }
    }

    /// The pass type's name without its module path (generic arguments kept), for messages.
    pub fn name(self) -> &'static str {
        self.name
    }
}

/// One stage of the plan: its id and the function that adds its pass when a view calls for it.
#[derive(Clone, Copy, Debug)]
pub struct Stage {
    /// Which stage (the type of the pass it adds).
    pub id: StageId,
    /// Adds the stage's passes, or none.
    pub plan: Planner,
}

impl Stage {
    /// The stage of pass type `P`, planned by `plan`.
    pub fn new<P: Pass>(plan: Planner) -> Stage {
        Stage { id: StageId::of::<P>(), plan }
    }
}

/// The built-in stages, in order.
pub fn builtin_stages() -> Vec<Stage> {
    use passes::*;
    vec![
        Stage::new::<ShadowMapsPass>(shadow_maps::plan),
        Stage::new::<DepthPrepass>(depth_prepass::plan),
        Stage::new::<ClusterDepthPass>(cluster_depth::plan),
        Stage::new::<ClusterBuildPass>(cluster_build::plan),
        Stage::new::<LightRefinePass>(light_refine::plan),
        Stage::new::<ForwardPass>(forward::plan),
        Stage::new::<ClusteredForwardPass>(clustered_forward::plan),
        Stage::new::<GBufferPass>(gbuffer::plan),
        Stage::new::<DeferredLightingPass>(deferred_lighting::plan),
        Stage::new::<TiledDeferredPass>(tiled_deferred::plan),
        Stage::new::<LightVolumesPass>(light_volumes::plan),
        Stage::new::<SkyboxPass>(skybox::plan),
        Stage::new::<TransparentPass>(transparent::plan),
        Stage::new::<MotionBlurPass>(motion_blur::plan),
        Stage::new::<BloomBrightPass>(bloom::plan),
        Stage::new::<TonemapPass>(tonemap::plan),
        Stage::new::<DebugViewPass>(debug_view::plan),
    ]
}

/// The stages a frame is planned with: the built-in ones and any an app added.
#[derive(Clone, Debug)]
pub struct FramePlanner {
    stages: Vec<Stage>,
}

impl Default for FramePlanner {
    fn default() -> Self {
        FramePlanner { stages: builtin_stages() }
    }
}

/// Why a stage could not be added.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum StageError {
    /// No stage has the pass type it was to be placed next to.
    #[error("no stage `{anchor}` to place `{stage}` next to (stages: {known})")]
    UnknownStage {
        /// The stage it was to be placed next to.
        anchor: &'static str,
        /// The stage that was to be added.
        stage: &'static str,
        /// The stages there are, in order.
        known: String,
    },
    /// A stage of that pass type exists already.
    #[error("a stage `{0}` exists already")]
    Duplicate(&'static str),
}

impl FramePlanner {
    /// Adds `stage` right after the stage of pass type `A`; refused, naming the stages there are,
    /// when there is none, or when a stage of the same pass type exists already.
    pub fn insert_after<A: Pass>(&mut self, stage: Stage) -> Result<(), StageError> {
        let at = self.position(StageId::of::<A>(), stage)?;
        self.stages.insert(at + 1, stage);
        Ok(())
    }

    /// Adds `stage` right before the stage of pass type `B` (refused as
    /// [`FramePlanner::insert_after`] is).
    pub fn insert_before<B: Pass>(&mut self, stage: Stage) -> Result<(), StageError> {
        let at = self.position(StageId::of::<B>(), stage)?;
        self.stages.insert(at, stage);
        Ok(())
    }

    /// Where `anchor` is, for adding `stage` next to it.
    fn position(&self, anchor: StageId, stage: Stage) -> Result<usize, StageError> {
        if self.contains(stage.id) {
            return Err(StageError::Duplicate(stage.id.name()));
        }
        self.stages.iter().position(|s| s.id == anchor).ok_or_else(|| StageError::UnknownStage {
            anchor: anchor.name(),
            stage: stage.id.name(),
            known: self.stages.iter().map(|s| s.id.name()).collect::<Vec<_>>().join(", "),
        })
    }

    /// True when a stage has id `id`.
    pub fn contains(&self, id: StageId) -> bool {
        self.stages.iter().any(|s| s.id == id)
    }

    /// The stages, in order.
    pub fn stages(&self) -> impl ExactSizeIterator<Item = StageId> + '_ {
        self.stages.iter().map(|s| s.id)
    }

    /// The passes `inputs` call for, stage after stage.
    pub fn passes(&self, inputs: &PlanInputs<'_>) -> Vec<Box<dyn Pass>> {
        let mut out = Vec::new();
        for stage in &self.stages {
            (stage.plan)(inputs, &mut out);
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
    use crate::context::RenderError;
    use crate::graph::{PassContext, ResourceName};
    use crate::passes::{BloomBrightPass, ClusteredForwardPass, TonemapPass};

    fn nothing(_: &PlanInputs<'_>, _: &mut Vec<Box<dyn Pass>>) {}

    /// A pass that records nothing; each `N` is a type of its own, so a stage of its own.
    struct Probe<const N: u8>;
    impl<const N: u8> Pass for Probe<N> {
        fn name(&self) -> &'static str {
            "probe"
        }
        fn reads(&self) -> Vec<ResourceName> {
            Vec::new()
        }
        fn writes(&self) -> Vec<ResourceName> {
            Vec::new()
        }
        fn record(&self, _: &mut PassContext<'_>) -> Result<(), RenderError> {
            Ok(())
        }
    }
    type Vignette = Probe<0>;
    type Grain = Probe<1>;

    #[test]
    fn a_stage_goes_next_to_a_known_one_and_never_silently_elsewhere() {
        let mut planner = FramePlanner::default();
        planner.insert_before::<TonemapPass>(Stage::new::<Vignette>(nothing)).expect("tonemap is a stage");
        let ids: Vec<StageId> = planner.stages().collect();
        let at = ids.iter().position(|s| *s == StageId::of::<Vignette>()).expect("added");
        assert_eq!(ids[at - 1], StageId::of::<BloomBrightPass>());
        assert_eq!(ids[at + 1], StageId::of::<TonemapPass>());
        // Grain is no stage: placing next to it is refused, naming the stages there are.
        let unknown = planner.insert_after::<Grain>(Stage::new::<Grain>(nothing)).unwrap_err();
        assert!(matches!(&unknown, StageError::UnknownStage { anchor: "Probe<1>", .. }), "{unknown}");
        assert!(unknown.to_string().contains("TonemapPass"), "{unknown}");
        assert_eq!(
            planner.insert_after::<ClusteredForwardPass>(Stage::new::<Vignette>(nothing)),
            Err(StageError::Duplicate("Probe<0>"))
        );
        assert_eq!(planner.stages().len(), builtin_stages().len() + 1);
        assert!(planner.contains(StageId::of::<Vignette>()) && !planner.contains(StageId::of::<Grain>()));
    }
}
