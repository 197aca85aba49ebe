//! The frame plan: which passes a view runs, as a pure function of the view.
//!
//! Each pass module says, next to its code, when its pass is needed: a `plan` function that
//! reads the view ([`PlanInputs`]) and adds its pass, or nothing.
//! [`FramePlanner`](crate::planner::FramePlanner) calls them stage after stage (the
//! [`builtin_stages`](crate::planner::builtin_stages) and any an app added), and the graph then
//! orders the passes by what they read and write.

use crate::graph::Pass;
use crate::snapshot::{DebugViewMode, FrameSettings, PipelineKind, RenderView, ViewComponents};

/// What a view's plan depends on.
#[derive(Clone, Copy, Debug)]
pub struct PlanInputs<'a> {
    /// The view: camera, image size, settings.
    pub view: &'a RenderView,
    /// Components an app extracted from the view's camera (its passes plan from them).
    pub components: &'a ViewComponents,
    /// The frame has a valid light (`FrameSnapshot::has_lights`).
    pub has_lights: bool,
    /// The frame draws a blended material (`FrameSnapshot::has_blended`).
    pub has_blended: bool,
    /// The frame brings its own per-pixel light lists (`FrameSnapshot::pixel_light_lists`):
    /// no cluster build.
    pub has_pixel_lists: bool,
    /// The frame has a light that casts a shadow with shadows enabled
    /// (`FrameSnapshot::casts_shadows`).
    pub casts_shadows: bool,
    /// Where light volumes sum their lights (`LightVolumesPass::accumulation_format` of the
    /// device; `HDR_FORMAT` when planning without one).
    pub accumulation: wgpu::TextureFormat,
}

impl PlanInputs<'_> {
    /// The view's settings.
    pub fn settings(&self) -> &FrameSettings {
        &self.view.settings
    }

    /// True when a debug view that needs neither lighting nor clusters replaces the image:
    /// albedo and normal draw the Full G-buffer, depth only the depth pre-pass.
    pub fn replaces_shading(&self) -> bool {
        self.shows_surfaces() || self.settings().debug_view == DebugViewMode::Depth
    }

    /// True when a debug view shows surface attributes (albedo, normal): the view draws the
    /// Full G-buffer instead of shading, in every pipeline.
    pub fn shows_surfaces(&self) -> bool {
        self.settings().debug_view.uses_surfaces()
    }

    /// True when the view shades with cluster lists (a tiled/clustered pipeline with lights).
    pub fn shades_with_clusters(&self) -> bool {
        self.settings().pipeline.uses_clusters() && self.has_lights && !self.replaces_shading()
    }

    /// True when the view shades lights that cast shadows (point, spot or directional): the
    /// shadow pass runs and every shading pass reads its atlas
    /// ([`crate::passes::SHADOW_ATLAS`]).
    pub fn shades_shadows(&self) -> bool {
        self.casts_shadows && !self.replaces_shading()
    }

    /// True when the view is shaded deferred: a G-buffer, then a full-screen lighting pass or
    /// light volumes. Without lights the forward pass draws the ambient.
    pub fn shades_deferred(&self) -> bool {
        self.settings().pipeline.is_deferred() && self.has_lights && !self.replaces_shading()
    }

    /// True when the view runs a depth pre-pass before forward clustered shading.
    pub fn runs_depth_prepass(&self) -> bool {
        let s = self.settings();
        self.shades_with_clusters()
            && !self.shades_deferred()
            && (s.pipeline == PipelineKind::ForwardPlus || s.clusters.depth_prepass)
    }

    /// True when every fragment the view shades has its shading distance known before the
    /// build: it shades with its own cluster lists (no per-pixel lists, no debug view) after a
    /// depth pre-pass or a G-buffer, and every fragment it shades is in that depth (no blended
    /// materials). Per-cluster depth bounds and refined lists rely on it.
    fn knows_shading_distances(&self) -> bool {
        self.shades_with_clusters()
            && self.shows_image()
            && !self.has_blended
            && !self.has_pixel_lists
            && (self.shades_deferred() || self.runs_depth_prepass())
    }

    /// True when the cluster build cuts clusters to their pixels' depth range
    /// ([`crate::snapshot::ClusterSettings::depth_bounds`]): the setting is on and the
    /// distances are known (`knows_shading_distances`).
    pub fn bounds_clusters_by_depth(&self) -> bool {
        self.settings().clusters.depth_bounds && self.knows_shading_distances()
    }

    /// True when the view refines its cluster lists per pixel block after the build
    /// ([`crate::snapshot::ClusterSettings::refined_lists`]): where the distances are known, as
    /// for [`Self::bounds_clusters_by_depth`], except tiled deferred, whose lighting pass cuts
    /// its tile lists itself.
    pub fn refines_lists(&self) -> bool {
        let s = self.settings();
        s.clusters.refined_lists
            && s.pipeline != PipelineKind::TiledDeferred
            && self.knows_shading_distances()
    }

    /// How the view's light lists are built: depth bounds and refined lists.
    pub fn list_options(&self) -> crate::clusters::ListOptions {
        crate::clusters::ListOptions {
            depth_bounds: self.bounds_clusters_by_depth(),
            refined_lists: self.refines_lists(),
        }
    }

    /// True when the depth pre-pass also writes each pixel's shading distance
    /// ([`crate::passes::SHADING_DISTANCE`]): a forward view bounding its clusters by depth or
    /// refining its lists.
    pub fn prepass_writes_distance(&self) -> bool {
        self.runs_depth_prepass() && (self.bounds_clusters_by_depth() || self.refines_lists())
    }

    /// True when no debug view replaces the image (post stages run).
    pub fn shows_image(&self) -> bool {
        self.settings().debug_view == DebugViewMode::None
    }
}

/// One stage of the plan: adds the passes it is needed for, or none.
pub type Planner = fn(&PlanInputs<'_>, &mut Vec<Box<dyn Pass>>);
