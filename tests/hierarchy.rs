//! Bevy's transform hierarchy and visibility in the plugin: lights and meshes placed by their
//! parents' `GlobalTransform`, a whole scene moved by its root, hidden entities not extracted.

mod support;

use manylight::app::headless::render_headless;
use manylight::app::{FrameStats, HeadlessCapture};
use manylight::prelude::*;
use support::{STRICT, assert_similar, gpu};

const SIZE: UVec2 = UVec2::new(128, 72);

/// Pixels whose colour differs by more than 8 levels in some channel.
fn changed_pixels(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    a.pixels().zip(b.pixels()).filter(|(p, q)| (0..3).any(|c| p.0[c].abs_diff(q.0[c]) > 8)).count()
}

/// Runs one update of a headless app and returns the frame it rendered.
fn next_frame(app: &mut App) -> image::RgbaImage {
    app.update();
    app.world_mut().resource_mut::<HeadlessCapture>().image.take().expect("a frame")
}

/// A bright light that makes a visible spot on the default scene's floor.
fn spot_light() -> PointLight {
    PointLight { color: Vec3::new(1.0, 0.3, 0.1), intensity: 1000.0, range: 5.0, radius: 0.0 }
}

/// The default scene with its camera and one light, placed by `light` in `Startup`.
fn render_with(light: impl Fn(&mut Commands) + Send + Sync + 'static) -> image::RgbaImage {
    let frame = render_headless(SIZE, 1, move |app| {
        app.add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &default_scene(), true, SIZE.x as f32 / SIZE.y as f32);
            light(&mut commands);
        });
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"));
    support::assert_finite(&frame);
    frame.image
}

/// A light that is the child of a moved, rotated and scaled parent lights the scene exactly
/// where its global position lies: the same image as the light spawned there directly.
#[test]
fn a_child_light_is_placed_by_its_parents_global_transform() {
    let _gpu = gpu();
    // Six units in front of the default scene's camera (at x = -18 looking down +X).
    let parent = Transform::from_xyz(-12.0, 0.5, -1.0)
        .with_rotation(Quat::from_rotation_y(std::f32::consts::FRAC_PI_2))
        .with_scale(Vec3::splat(2.0));
    let local = Vec3::new(0.5, 0.25, 0.0);
    let world = parent.transform_point(local);
    let nested = render_with(move |commands| {
        let p = commands.spawn(parent).id();
        commands.spawn((Transform::from_translation(local), spot_light(), ChildOf(p)));
    });
    let direct = render_with(move |commands| {
        commands.spawn((Transform::from_translation(world), spot_light()));
    });
    let unmoved = render_with(move |commands| {
        commands.spawn((Transform::from_translation(local), spot_light()));
    });
    assert_similar("hierarchy_child_light", &direct, &nested, STRICT);
    let changed = changed_pixels(&unmoved, &nested);
    assert!(changed > 100, "the parent's transform changed {changed} pixels");
}

/// Moving a parent in `Update` moves its child lights in the next rendered frame.
#[test]
fn moving_a_parent_moves_its_child_lights_in_the_image() {
    let _gpu = gpu();
    #[derive(Component)]
    struct Arm;
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE)).add_systems(Startup, |mut commands: Commands| {
        spawn_scene(&mut commands, &default_scene(), true, SIZE.x as f32 / SIZE.y as f32);
        let arm = commands.spawn((Transform::from_xyz(-12.0, 0.5, -2.0), Arm)).id();
        for x in [-0.5, 0.5] {
            commands.spawn((Transform::from_xyz(x, 0.0, 0.0), spot_light(), ChildOf(arm)));
        }
    });
    let before = next_frame(&mut app);
    let mut arms = app.world_mut().query_filtered::<&mut Transform, With<Arm>>();
    for mut t in arms.iter_mut(app.world_mut()) {
        t.translation.z += 4.0;
    }
    let after = next_frame(&mut app);
    let again = next_frame(&mut app);
    let changed = changed_pixels(&before, &after);
    assert!(changed > 100, "moving the parent changed {changed} pixels");
    assert_similar("hierarchy_moved_parent_still", &after, &again, STRICT);
}

/// Moving a scene's root moves every mesh and light of it (the camera framing it stays).
#[test]
fn moving_a_scene_root_moves_the_whole_scene() {
    let _gpu = gpu();
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE)).add_systems(Startup, |mut commands: Commands| {
        let mut scene = default_scene();
        scene.cameras.clear(); // a framing camera at the top level, outside the scene root
        spawn_scene(&mut commands, &scene, true, SIZE.x as f32 / SIZE.y as f32);
    });
    let before = next_frame(&mut app);
    let mut roots = app.world_mut().query::<(&manylight::app::scene::SceneRoot, &mut Transform)>();
    let (_, mut root) = roots.single_mut(app.world_mut()).expect("one scene root");
    root.translation.y -= 1.0;
    let after = next_frame(&mut app);
    let changed = changed_pixels(&before, &after);
    assert!(changed > 100, "moving the scene root changed {changed} pixels");
    let children = app.world_mut().query::<(&ChildOf, &Mesh3d)>().iter(app.world()).count();
    assert_eq!(children, default_scene().instances.len(), "every instance is a child of the root");
}

/// Hidden meshes and lights are not extracted: the frame has the draws and lights of the
/// visible ones only, a `Hidden` parent hides the children that inherit, and a `Visible`
/// child shows under it.
#[test]
fn hidden_entities_produce_no_draws_and_no_lights() {
    let _gpu = gpu();
    let counts = |hide: bool| {
        let frame = render_headless(SIZE, 1, move |app| {
            app.add_systems(Startup, move |mut commands: Commands| {
                let root = spawn_scene(&mut commands, &default_scene(), true, 1.5);
                let group =
                    commands.spawn(if hide { Visibility::Hidden } else { Visibility::Inherited }).id();
                for i in 0..10 {
                    commands.spawn((
                        Transform::from_xyz(i as f32 - 5.0, 1.0, 0.0),
                        spot_light(),
                        ChildOf(group),
                    ));
                }
                // Shown whatever its parent says.
                commands.spawn((
                    Transform::from_xyz(0.0, 2.0, 0.0),
                    spot_light(),
                    Visibility::Visible,
                    ChildOf(group),
                ));
                if hide {
                    // A hidden light and a hidden mesh of their own.
                    commands.spawn((Transform::from_xyz(1.0, 1.0, 1.0), spot_light(), Visibility::Hidden));
                    commands.entity(root).insert(Visibility::Hidden);
                }
            });
        })
        .unwrap_or_else(|e| panic!("render failed: {e}"));
        let report = frame.stats.last.expect("a report");
        (report.light_count, report.instance_count)
    };
    let scene = default_scene();
    let (lights, instances) = counts(false);
    assert_eq!((lights as usize, instances as usize), (scene.lights.len() + 11, scene.instances.len()));
    let (lights, instances) = counts(true);
    assert_eq!((lights, instances), (1, 0), "only the Visible child of the hidden group is extracted");
}

/// `Time` drives the light rigs: with the headless fixed step, the second frame is
/// `HEADLESS_TIME_STEP` later than the first, the first is at 0.
#[test]
fn time_advances_by_the_headless_step() {
    let _gpu = gpu();
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(UVec2::new(16, 16)));
    app.update();
    assert_eq!(app.world().resource::<Time>().elapsed_secs(), 0.0);
    app.update();
    app.update();
    let elapsed = app.world().resource::<Time>().elapsed();
    assert_eq!(elapsed, manylight::app::HEADLESS_TIME_STEP * 2);
    assert!(app.world().resource::<FrameStats>().last.is_some());
}

/// A glTF scene spawns its node tree: one entity per node with the file's parentage (under the
/// scene root), its meshes and lights as children of their node, each at the world transform
/// the loader computed by composing the nodes (CesiumMan: 22 nested nodes; NegativeScaleTest:
/// mirrored parents; LightsPunctualLamp: lights on nodes).
#[test]
fn a_gltf_node_tree_spawns_as_entities_with_its_parentage() {
    let _gpu = gpu();
    let (mut nested, mut lit) = (false, false);
    for asset in [
        "CesiumMan/CesiumMan.gltf",
        "NegativeScaleTest/NegativeScaleTest.gltf",
        "LightsPunctualLamp/LightsPunctualLamp.gltf",
    ] {
        let (nodes, lights) = check_spawned_tree(asset);
        nested |= nodes;
        lit |= lights > 0;
    }
    assert!(nested && lit, "the assets have nested nodes and lights");
}

/// Spawns `asset` and checks its entity tree against the loaded scene; returns whether the
/// tree has nested nodes and how many lights it spawned.
fn check_spawned_tree(asset: &str) -> (bool, usize) {
    let path = support::asset(asset);
    let scene = manylight::scene::load_gltf(&path, &Default::default()).expect("loads");
    let expected = scene.clone();
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(UVec2::new(32, 32))).add_systems(
        Startup,
        move |mut commands: Commands| {
            spawn_scene(&mut commands, &scene, true, 1.0);
        },
    );
    app.update();
    let world = app.world_mut();
    let root = world
        .query_filtered::<Entity, With<manylight::app::scene::SceneRoot>>()
        .single(world)
        .expect("a root");
    let nodes: std::collections::HashMap<Entity, usize> = world
        .query::<(Entity, &manylight::app::scene::SceneNodeIndex)>()
        .iter(world)
        .map(|(e, i)| (e, i.0))
        .collect();
    assert_eq!(nodes.len(), expected.nodes.len(), "{asset}: one entity per node");
    let mut index_to_entity = vec![Entity::PLACEHOLDER; nodes.len()];
    for (&e, &i) in &nodes {
        index_to_entity[i] = e;
    }
    for (i, node) in expected.nodes.iter().enumerate() {
        let parent = world.get::<ChildOf>(index_to_entity[i]).expect("every node has a parent").parent();
        let want = node.parent.map_or(root, |p| index_to_entity[p]);
        assert_eq!(parent, want, "{asset}: node {i} ({:?})", node.name);
    }
    // Meshes and lights hang from their nodes, at the loader's world transforms.
    let mut meshes = 0;
    for (child_of, global, _) in world.query::<(&ChildOf, &GlobalTransform, &Mesh3d)>().iter(world) {
        let node = nodes[&child_of.parent()];
        let matches = expected.nodes[node]
            .instances
            .iter()
            .any(|&k| global.to_matrix().abs_diff_eq(expected.instances[k].transform, 1e-4));
        assert!(matches, "{asset}: a mesh of node {node} is not at any of its instances' transforms");
        meshes += 1;
    }
    assert_eq!(meshes, expected.instances.len(), "{asset}");
    let mut lights = 0;
    for (child_of, global, _) in world.query::<(&ChildOf, &GlobalTransform, &PointLight)>().iter(world) {
        let node = nodes[&child_of.parent()];
        let at = global.translation();
        let matches =
            expected.nodes[node].lights.iter().any(|&k| (expected.lights[k].position - at).length() < 1e-4);
        assert!(matches, "{asset}: a light of node {node} at {at} is not where the loader put it");
        lights += 1;
    }
    assert_eq!(lights, expected.lights.len(), "{asset}");
    (expected.nodes.iter().any(|n| n.parent.is_some()), lights)
}
