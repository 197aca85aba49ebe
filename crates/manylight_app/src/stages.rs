//! Passes an app adds from outside the crates: stages placed next to the built-in ones by type
//! ([`RenderStages`], [`ManyLightAppExt`]), and camera components copied into each view for
//! them ([`ExtractCameraComponentPlugin`], as Bevy's `ExtractComponentPlugin`).
//!
//! ```no_run
//! use manylight_app::prelude::*;
//! use manylight_render::passes::TonemapPass;
//! # use manylight_render::{Pass, PassContext, PlanInputs, RenderError, ResourceName};
//! # struct VignettePass;
//! # impl Pass for VignettePass {
//! #     fn name(&self) -> &'static str { "vignette" }
//! #     fn reads(&self) -> Vec<ResourceName> { Vec::new() }
//! #     fn writes(&self) -> Vec<ResourceName> { Vec::new() }
//! #     fn record(&self, _: &mut PassContext<'_>) -> Result<(), RenderError> { Ok(()) }
//! # }
//! #[derive(Component, Clone)]
//! struct Vignette { strength: f32 }
//!
//! /// Adds the pass to views whose camera has a `Vignette`.
//! fn plan_vignette(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn Pass>>) {
//!     if p.components.get::<Vignette>().is_some() && p.shows_image() {
//!         out.push(Box::new(VignettePass));
//!     }
//! }
//!
//! let mut app = App::new();
//! app.add_plugins((ManyLightPlugin::default(), ExtractCameraComponentPlugin::<Vignette>::default()));
//! app.add_render_stage_before::<TonemapPass>(Stage::new::<VignettePass>(plan_vignette))
//!     .expect("tone mapping is a stage");
//! ```

use crate::components::Camera3d;
use bevy_app::prelude::*;
use bevy_ecs::prelude::*;
use manylight_render::{FramePlanner, Pass, Stage, StageError, ViewComponents};
use std::collections::HashMap;
use std::marker::PhantomData;
use std::sync::Arc;

/// Public system sets, so user systems can be ordered around the plugin's.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ManyLightSystems {
    /// `Update`: the plugin's own animation (light rigs). User systems that move things can
    /// run before or after it.
    Animate,
    /// `Last`: the snapshot of the world is taken and handed to the renderer. Anything that
    /// should show in this frame must run before it (any `Update` system does).
    Extract,
}

/// The stages views are planned with: the built-in ones and those the app added. Extraction
/// hands them to the render world with each frame
/// ([`crate::render_world::RenderWorld::set_stages`]), shared, not copied.
#[derive(Resource, Clone, Debug, Default)]
pub struct RenderStages(pub Arc<FramePlanner>);

impl RenderStages {
    /// Adds `stage` right before the stage of pass type `B`; an error when there is none, or
    /// when a stage of the same pass type exists already.
    pub fn insert_before<B: Pass>(&mut self, stage: Stage) -> Result<(), StageError> {
        Arc::make_mut(&mut self.0).insert_before::<B>(stage)
    }

    /// Adds `stage` right after the stage of pass type `A` (errors as
    /// [`RenderStages::insert_before`]).
    pub fn insert_after<A: Pass>(&mut self, stage: Stage) -> Result<(), StageError> {
        Arc::make_mut(&mut self.0).insert_after::<A>(stage)
    }
}

/// Adding render stages to an `App`.
pub trait ManyLightAppExt {
    /// Adds `stage` right before the stage of pass type `B` ([`RenderStages::insert_before`]).
    fn add_render_stage_before<B: Pass>(&mut self, stage: Stage) -> Result<&mut Self, StageError>;
    /// Adds `stage` right after the stage of pass type `A` ([`RenderStages::insert_after`]).
    fn add_render_stage_after<A: Pass>(&mut self, stage: Stage) -> Result<&mut Self, StageError>;
}

impl ManyLightAppExt for App {
    fn add_render_stage_before<B: Pass>(&mut self, stage: Stage) -> Result<&mut Self, StageError> {
        self.world_mut().get_resource_or_init::<RenderStages>().insert_before::<B>(stage)?;
        Ok(self)
    }

    fn add_render_stage_after<A: Pass>(&mut self, stage: Stage) -> Result<&mut Self, StageError> {
        self.world_mut().get_resource_or_init::<RenderStages>().insert_after::<A>(stage)?;
        Ok(self)
    }
}

/// Each camera's components extracted this frame for the app's passes (emptied by extraction,
/// which moves them into the frame's views).
#[derive(Resource, Default, Debug)]
pub struct ExtractedCameraComponents(pub HashMap<Entity, ViewComponents>);

/// Copies component `C` of every `Camera3d` into its view each frame
/// ([`manylight_render::ExtractedView::components`]), where a stage's plan function finds it
/// (`PlanInputs::components.get::<C>()`): the pass runs only for cameras that carry it.
pub struct ExtractCameraComponentPlugin<C>(PhantomData<fn() -> C>);

impl<C> Default for ExtractCameraComponentPlugin<C> {
    fn default() -> Self {
        Self(PhantomData)
    }
}

impl<C: Component + Clone + Send + Sync + 'static> Plugin for ExtractCameraComponentPlugin<C> {
    fn build(&self, app: &mut App) {
        app.init_resource::<ExtractedCameraComponents>()
            .add_systems(Last, extract_camera_component::<C>.before(ManyLightSystems::Extract));
    }
}

/// Copies each camera's `C` into [`ExtractedCameraComponents`].
fn extract_camera_component<C: Component + Clone + Send + Sync + 'static>(
    cameras: Query<(Entity, &C), With<Camera3d>>,
    mut out: ResMut<ExtractedCameraComponents>,
) {
    for (entity, component) in &cameras {
        out.0.entry(entity).or_default().insert(component.clone());
    }
}
