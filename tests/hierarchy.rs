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
    PointLight {
        color: Color::linear_rgb(1.0, 0.3, 0.1),
        intensity: 1000.0,
        range: 5.0,
        radius: 0.0,
        ..Default::default()
    }
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

// --- Visibility propagation without rendering: `propagate_visibility` alone in a bare world.

use manylight::app::visibility::{VisibilityUpdateStats, propagate_visibility};

/// A bare world running `propagate_visibility` as its only system, one frame per `frame()`,
/// with the system's [`VisibilityUpdateStats`] recorded.
struct VisWorld {
    world: World,
    schedule: Schedule,
}

impl VisWorld {
    fn new() -> Self {
        let mut world = World::new();
        world.init_resource::<VisibilityUpdateStats>();
        let mut schedule = Schedule::default();
        schedule.add_systems(propagate_visibility);
        VisWorld { world, schedule }
    }

    /// Runs one frame and checks that every `InheritedVisibility` it wrote changed value;
    /// returns what the system reported.
    fn frame(&mut self) -> VisibilityUpdateStats {
        let mut values = self.world.query::<(Entity, &InheritedVisibility)>();
        let before: std::collections::HashMap<Entity, bool> =
            values.iter(&self.world).map(|(e, v)| (e, v.0)).collect();
        // The edits made so far carry this tick; the system's writes a later one.
        let edits = self.world.increment_change_tick();
        self.schedule.run(&mut self.world);
        let now = self.world.change_tick();
        let mut written = 0;
        let mut refs = self.world.query::<(Entity, Ref<InheritedVisibility>)>();
        for (e, v) in refs.iter(&self.world) {
            if v.last_changed().is_newer_than(edits, now) {
                written += 1;
                assert_ne!(before.get(&e), Some(&v.0), "{e} was written without changing");
            }
        }
        self.world.clear_trackers();
        let stats = *self.world.resource::<VisibilityUpdateStats>();
        assert_eq!(stats.written, written, "the system's count of writes");
        stats
    }

    /// The stored value of `entity`.
    fn shown(&self, entity: Entity) -> bool {
        self.world.get::<InheritedVisibility>(entity).expect("an InheritedVisibility").0
    }

    /// Checks every entity with a `Visibility` against [`reference_visibility`].
    fn check(&mut self, context: &str) {
        let mut q = self.world.query_filtered::<(Entity, &InheritedVisibility), With<Visibility>>();
        for (e, v) in q.iter(&self.world) {
            assert_eq!(v.0, reference_visibility(&self.world, e), "{context}: {e}");
        }
    }
}

/// The brute-force value: walk the ancestors until one decides (`Hidden`, `Visible`) or the
/// root (visible); an entity without a `Visibility` counts as `Inherited`.
fn reference_visibility(world: &World, entity: Entity) -> bool {
    let mut current = entity;
    loop {
        match world.get::<Visibility>(current).copied().unwrap_or_default() {
            Visibility::Hidden => return false,
            Visibility::Visible => return true,
            Visibility::Inherited => {}
        }
        match world.get::<ChildOf>(current) {
            Some(child_of) => current = child_of.parent(),
            None => return true,
        }
    }
}

/// A small deterministic generator (xorshift64*), so that a failing seed reproduces.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    /// A random `Visibility`, or none.
    fn visibility(&mut self) -> Option<Visibility> {
        [None, Some(Visibility::Inherited), Some(Visibility::Hidden), Some(Visibility::Visible)]
            [self.below(4)]
    }
}

/// Spawns an entity with `visibility` (or none) under `parent` (or as a root).
fn spawn_node(world: &mut World, visibility: Option<Visibility>, parent: Option<Entity>) -> Entity {
    let mut entity = world.spawn_empty();
    if let Some(v) = visibility {
        entity.insert(v);
    }
    if let Some(p) = parent {
        entity.insert(ChildOf(p));
    }
    entity.id()
}

/// Whether `ancestor` is `entity` or one of its ancestors.
fn is_ancestor(world: &World, ancestor: Entity, entity: Entity) -> bool {
    let mut current = Some(entity);
    while let Some(e) = current {
        if e == ancestor {
            return true;
        }
        current = world.get::<ChildOf>(e).map(ChildOf::parent);
    }
    false
}

/// Random forests with random `Visibility` values, edited at random over many frames (every
/// kind of change: `Visibility` set, touched, added and removed; reparenting; becoming a root;
/// children spawned under existing and new parents, children before parents; despawns;
/// `InheritedVisibility` overwritten by someone else), match the brute-force reference after
/// every frame, write only values that change, and a frame without edits does nothing.
#[test]
fn visibility_propagation_matches_the_reference_under_random_edits() {
    for seed in 1..=32u64 {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ seed.wrapping_mul(0x1000_0000_01b3));
        let mut vis = VisWorld::new();
        let mut live: Vec<Entity> = Vec::new();
        for _ in 0..80 {
            let parent =
                if live.is_empty() || rng.below(6) == 0 { None } else { Some(live[rng.below(live.len())]) };
            let v = rng.visibility();
            live.push(spawn_node(&mut vis.world, v, parent));
        }
        vis.frame();
        vis.check(&format!("seed {seed}, first frame"));
        for frame in 0..60 {
            for _ in 0..1 + rng.below(6) {
                live.retain(|&e| vis.world.get_entity(e).is_ok());
                if live.is_empty() {
                    live.push(spawn_node(&mut vis.world, rng.visibility(), None));
                }
                let e = live[rng.below(live.len())];
                let world = &mut vis.world;
                match rng.below(11) {
                    0 | 1 => match rng.visibility() {
                        Some(v) => {
                            world.entity_mut(e).insert(v);
                        }
                        None => {
                            world.entity_mut(e).remove::<Visibility>();
                        }
                    },
                    2 => {
                        let p = live[rng.below(live.len())];
                        if !is_ancestor(world, e, p) {
                            world.entity_mut(e).insert(ChildOf(p));
                        }
                    }
                    3 => {
                        world.entity_mut(e).remove::<ChildOf>();
                    }
                    4 => {
                        world.entity_mut(e).remove::<Visibility>();
                    }
                    5 => {
                        let v = rng.visibility();
                        live.push(spawn_node(world, v, Some(e)));
                    }
                    6 if live.len() > 10 => world.entity_mut(e).despawn(),
                    7 => {
                        // Written with the same value: changed, not different.
                        if let Some(mut v) = world.get_mut::<Visibility>(e) {
                            v.set_changed();
                        }
                    }
                    8 => {
                        if let Some(mut v) = world.get_mut::<InheritedVisibility>(e) {
                            v.0 = !v.0;
                        }
                    }
                    9 => {
                        // A child spawned before its new parent, the parent under `e`.
                        let (cv, pv) = (rng.visibility(), rng.visibility());
                        let child = spawn_node(world, cv, None);
                        let parent = spawn_node(world, pv, Some(e));
                        world.entity_mut(child).insert(ChildOf(parent));
                        live.extend([child, parent]);
                    }
                    _ => {
                        // A parent and one of its descendants both changed in one frame.
                        let v = rng.visibility().unwrap_or(Visibility::Hidden);
                        world.entity_mut(e).insert(v);
                        if let Some(parent) = world.get::<ChildOf>(e).map(ChildOf::parent) {
                            let v = rng.visibility().unwrap_or(Visibility::Visible);
                            world.entity_mut(parent).insert(v);
                        }
                    }
                }
            }
            vis.frame();
            vis.check(&format!("seed {seed}, frame {frame}"));
            if frame % 8 == 0 {
                let idle = vis.frame();
                assert_eq!(
                    idle,
                    VisibilityUpdateStats::default(),
                    "seed {seed}, frame {frame}: an idle frame"
                );
            }
        }
    }
}

/// A change at the top of a chain and a change below a clean entity whose stored value is
/// about to go stale, in one frame: the lower one must not trust the stale value.
#[test]
fn a_changed_child_under_a_stale_clean_parent_ends_correct() {
    let mut vis = VisWorld::new();
    let top = spawn_node(&mut vis.world, Some(Visibility::Inherited), None);
    let middle = spawn_node(&mut vis.world, Some(Visibility::Inherited), Some(top));
    let bottom = spawn_node(&mut vis.world, Some(Visibility::Inherited), Some(middle));
    let leaves: Vec<Entity> =
        (0..4).map(|_| spawn_node(&mut vis.world, Some(Visibility::Inherited), Some(bottom))).collect();
    vis.frame();
    assert!(vis.shown(bottom));
    vis.world.entity_mut(top).insert(Visibility::Hidden);
    vis.world.entity_mut(bottom).insert(Visibility::Inherited);
    vis.world.entity_mut(leaves[0]).insert(Visibility::Inherited);
    vis.frame();
    vis.check("top hidden");
    assert!(!vis.shown(middle) && !vis.shown(bottom) && leaves.iter().all(|&l| !vis.shown(l)));
}

/// An entity without a `Visibility` passes its parent's value through; when it gains one that
/// equals its left-over `InheritedVisibility`, its children still get the new value.
#[test]
fn gaining_visibility_over_a_left_over_value_reaches_the_children() {
    let mut vis = VisWorld::new();
    let group = spawn_node(&mut vis.world, Some(Visibility::Hidden), None);
    let child = spawn_node(&mut vis.world, Some(Visibility::Inherited), Some(group));
    vis.frame();
    assert!(!vis.shown(child));
    // Without a `Visibility` the group counts as `Inherited` (its own stored value stays).
    vis.world.entity_mut(group).remove::<Visibility>();
    vis.frame();
    assert!(vis.shown(child), "the group passes the root's visible through");
    assert!(!vis.shown(group), "an entity without Visibility keeps its InheritedVisibility");
    vis.world.entity_mut(group).insert(Visibility::Hidden);
    vis.frame();
    assert!(!vis.shown(child), "hidden again, though the group's stored value did not change");
    // Becoming a root, and a despawned parent's messages, leave the rest consistent.
    vis.world.entity_mut(child).remove::<ChildOf>();
    vis.frame();
    assert!(vis.shown(child));
    vis.world.entity_mut(group).despawn();
    assert_eq!(vis.frame().dirty, 0, "a despawned entity has nothing to update");
    vis.check("after the despawn");
}

/// A chain of 1,023 `Inherited` nodes above 100,000 instances settles in one pass on its first
/// frame (each entity resolved once, not once per ancestor), and later frames cost what
/// changed: nothing when nothing did, one entity for one instance, the subtree whose value
/// changes when the top of the chain hides it (not what a `Visible` entity shields).
#[test]
fn a_deep_chain_above_many_instances_settles_in_one_pass() {
    const DEPTH: usize = 1023;
    const INSTANCES: usize = 100_000;
    let mut vis = VisWorld::new();
    let top = spawn_node(&mut vis.world, Some(Visibility::Inherited), None);
    let mut leaf = top;
    for _ in 1..DEPTH {
        leaf = spawn_node(&mut vis.world, Some(Visibility::Inherited), Some(leaf));
    }
    let instances: Vec<Entity> =
        vis.world.spawn_batch((0..INSTANCES).map(move |_| (Visibility::Inherited, ChildOf(leaf)))).collect();
    let all = DEPTH + INSTANCES;
    // Beside the chain: a `Visible` entity with instances of its own, kept visible.
    let shield = spawn_node(&mut vis.world, Some(Visibility::Visible), Some(top));
    for _ in 0..1000 {
        spawn_node(&mut vis.world, Some(Visibility::Inherited), Some(shield));
    }

    let first = vis.frame();
    assert_eq!(first.dirty, all + 1001);
    assert!(first.resolved <= all + 1001, "{first:?}");
    // The freshly added values are not trusted: each parent looks at its children once.
    assert!(first.propagated <= all + 1001, "{first:?}");
    assert_eq!(first.written, 0, "everything is visible, as the default");
    assert!(instances.iter().all(|&i| vis.shown(i)));

    assert_eq!(vis.frame(), VisibilityUpdateStats::default(), "nothing changed");

    vis.world.entity_mut(top).insert(Visibility::Hidden);
    let hidden = vis.frame();
    assert_eq!((hidden.dirty, hidden.resolved, hidden.written), (1, 1, all), "{hidden:?}");
    // Below the top: the rest of the chain, its instances and the shield, not what it shields.
    assert_eq!(hidden.propagated, (DEPTH - 1) + INSTANCES + 1, "{hidden:?}");
    assert!(instances.iter().all(|&i| !vis.shown(i)) && vis.shown(shield));

    vis.world.entity_mut(instances[7]).insert(Visibility::Visible);
    let one = vis.frame();
    assert_eq!(one, VisibilityUpdateStats { dirty: 1, resolved: 1, propagated: 0, written: 1 });

    // A new instance resolves through the chain (memoised: each ancestor once) up to the
    // hidden top.
    let late = vis.world.spawn((Visibility::Inherited, ChildOf(leaf))).id();
    let spawned = vis.frame();
    assert_eq!((spawned.dirty, spawned.written), (1, 1), "{spawned:?}");
    assert!(spawned.resolved <= DEPTH + 1, "{spawned:?}");
    assert!(!vis.shown(late));
    // The bottom of the chain made `Visible` shows every instance below it, nothing above.
    vis.world.entity_mut(leaf).insert(Visibility::Visible);
    let shown = vis.frame();
    assert_eq!(shown.written, 1 + INSTANCES, "{shown:?}");
    assert!(vis.shown(late) && vis.shown(instances[0]) && !vis.shown(top));
}

/// Through the plugin, frame by frame: hiding a group hides its lights in the next frame, a
/// frame without edits writes no `InheritedVisibility`, and a subgroup without a `Visibility`
/// moved to the top level shows again.
#[test]
fn visibility_changes_reach_the_extracted_lights_frame_by_frame() {
    let _gpu = gpu();
    #[derive(Component)]
    struct Group;
    #[derive(Component)]
    struct Subgroup;
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(UVec2::new(32, 32))).add_systems(
        Startup,
        |mut commands: Commands| {
            commands.spawn((Transform::from_xyz(0.0, 1.0, 5.0), Camera3d));
            let group = commands.spawn((Transform::IDENTITY, Visibility::Inherited, Group)).id();
            for x in 0..3 {
                commands.spawn((Transform::from_xyz(x as f32, 0.0, 0.0), spot_light(), ChildOf(group)));
            }
            // No `Visibility`: it passes the group's through.
            let sub = commands.spawn((Transform::IDENTITY, Subgroup, ChildOf(group))).id();
            for x in 0..2 {
                commands.spawn((Transform::from_xyz(x as f32, 1.0, 0.0), spot_light(), ChildOf(sub)));
            }
        },
    );
    let lights = |app: &mut App| {
        app.update();
        app.world().resource::<FrameStats>().last.as_ref().expect("a report").light_count
    };
    assert_eq!(lights(&mut app), 5);
    let group = app.world_mut().query_filtered::<Entity, With<Group>>().single(app.world()).expect("a group");
    app.world_mut().entity_mut(group).insert(Visibility::Hidden);
    assert_eq!(lights(&mut app), 0, "the hidden group's lights, its subgroup's included");
    // One more frame without edits: no `InheritedVisibility` written in it.
    let before = app.world_mut().increment_change_tick();
    assert_eq!(lights(&mut app), 0);
    let now = app.world_mut().change_tick();
    let mut values = app.world_mut().query::<Ref<InheritedVisibility>>();
    let written = values.iter(app.world()).filter(|v| v.last_changed().is_newer_than(before, now)).count();
    assert_eq!(written, 0, "a frame without edits writes nothing");
    let sub =
        app.world_mut().query_filtered::<Entity, With<Subgroup>>().single(app.world()).expect("a subgroup");
    app.world_mut().entity_mut(sub).remove::<ChildOf>();
    assert_eq!(lights(&mut app), 2, "the subgroup, now a root, shows");
    app.world_mut().entity_mut(group).insert(Visibility::Visible);
    assert_eq!(lights(&mut app), 5);
}

/// A `ChildOf` cycle (which Bevy does not refuse) ends the walk at the number of entities
/// instead of looping forever.
#[test]
fn a_childof_cycle_does_not_hang_the_update() {
    let mut vis = VisWorld::new();
    let a = spawn_node(&mut vis.world, Some(Visibility::Inherited), None);
    let b = spawn_node(&mut vis.world, None, Some(a));
    let c = spawn_node(&mut vis.world, Some(Visibility::Hidden), Some(b));
    vis.frame();
    vis.world.entity_mut(a).insert(ChildOf(b));
    vis.frame();
    assert!(vis.shown(a), "at the end of the walk, visible like a root");
    vis.world.entity_mut(a).insert(Visibility::Hidden);
    vis.frame();
    assert!(!vis.shown(a) && !vis.shown(c));
}
