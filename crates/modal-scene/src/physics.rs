//! The rapier3d world of a scene and what one step reports.
//!
//! Bodies: a dynamic object gets the **mass, centre of mass and inertia of
//! its bank** (the tet mesh's exact integrals) as explicit mass properties;
//! its collider ([`crate::collider`]: the convex hull of the bank's surface
//! nodes, or a convex decomposition) has zero density, so the collider shape
//! never changes the dynamics. A fixed object uses a triangle mesh of its
//! surface. The body frame is the mesh frame, so
//! contact points in collider coordinates are directly points of the bank's
//! surface. The ground is a half-space `y ≥ height` pointing up.
//!
//! **Rolling resistance.** A rigid hull rolling or rocking on a rigid floor
//! loses no energy in rapier, so a bowl would rock on its faceted hull for
//! ever and never sleep. Real contacts dissipate through the deformation of
//! the contact patch, modelled (as in textbook rolling resistance) by a
//! couple `b·N` opposing the rotation, with `N` the normal contact force and
//! `b` a lever arm of the order of the patch half-width (per object,
//! `rolling_resistance`, default 1 mm). Per step each awake dynamic body
//! receives the angular impulse `−ω̂ · min(b·J_n, |ω| / (ω̂ᵀ I⁻¹ ω̂))`, where
//! `J_n` is the step's total normal contact impulse on it, capped at
//! [`ROLLING_LOAD_CAP`] `· m·|g|·dt` (the couple models the resting load, not
//! impacts): the clamp stops the rotation instead of reversing it. Free flight is unaffected (no
//! contact, no couple). Bodies then come to rest and fall asleep under
//! rapier's sleep rule, every point slower than [`SLEEP_SPEED_M_S`] (rapier's
//! own 0.1 m/s, sized for metre-scale bodies, froze a block sliding at 9 cm/s
//! on ice after 1.8 cm, and a bar drifting at 5 cm/s in mid-air), after
//! [`SLEEP_AFTER_S`] instead of rapier's 0.5 s: a bouncing or rocking body
//! passes below the threshold only for a few milliseconds at its turning
//! points, and a sleeping body is woken by anything that touches it.
//!
//! **Contact prediction.** Rapier creates speculative contacts between
//! shapes closer than its prediction distance, by default 2 cm — sized for
//! metre-scale bodies. On a fine fixed mesh that widens every query box of
//! a centimetre body by 2 cm on each side: the roll scene's 12 mm ball in
//! its fixed bowl collected ≈ 3× the triangles it can touch each step. A
//! scene may set it (`contact_prediction`, metres); below the distance a
//! body travels per step (short of rapier's CCD threshold, half its
//! thinnest extent) contacts can be missed: a 1 cm ball dropped into a
//! decomposed (dynamic) bowl fell through its bottom at 5 and 10 mm.
//!
//! **Bodies set touching.** parry's contact query between two convex hulls
//! is unreliable when they start within a few µm of each other with faces
//! flush (GJK at a degenerate simplex): a bar set on a bar got a sideways or
//! inverted normal (separation −4 cm) on the first step and was pushed into
//! the bar below, then thrown out at metres per second. So before the first
//! step each dynamic body closer than [`START_GAP_M`] to a body below it is
//! lifted to that gap ([`open_start_gaps`]); the first query then sees two
//! separated shapes, and the body settles onto the other through rapier's
//! speculative contact, without an impact (`tests/stacks.rs`). Fixed convex
//! bodies collide as their hull, not their triangle mesh, for the same
//! reason ([`crate::collider`]).
//!
//! Stepping is single-threaded with a fixed `dt = 1/physics_rate` and the
//! Coulomb friction model (one friction constraint per contact point), so the
//! per-point friction impulse is meaningful and runs are bit-reproducible.

use std::sync::Arc;

use modal_bank::ModeBank;
use modal_fem::Material;
use rapier3d::prelude::*;

use crate::collider::{surface_points, surface_triangles, ShapeCache};
use crate::face_hull::FaceHull;
use crate::material::{plane_strain_modulus, resolve_material};
use crate::roughness::{object_surface, resolve_surface, SurfaceFinish};
use crate::spec::{BodyKind, Scene};
use crate::SceneError;

/// A dynamic body whose every point moves slower than [`SLEEP_SPEED_M_S`]
/// for this long falls asleep [s] (rapier's default is 0.5 s).
pub const SLEEP_AFTER_S: f64 = 0.2;

/// Speed below which every point of a body must stay for [`SLEEP_AFTER_S`]
/// before it sleeps [m/s] (module doc; rapier's default is 0.1 m/s).
pub const SLEEP_SPEED_M_S: f64 = 0.01;

/// The normal impulse entering the rolling-resistance couple is capped at
/// this many times the body's weight impulse `m·|g|·dt`: the couple models
/// the resting or rolling load, not the brief impulses of impacts (their
/// losses are the restitution's business).
pub const ROLLING_LOAD_CAP: f64 = 2.0;

/// `user_data` of the ground collider.
const GROUND: u128 = u128::MAX;

/// What the contact model needs to know about one side of a contact.
#[derive(Clone, Debug)]
pub struct ContactSide {
    /// Object index, `None` for the ground.
    pub object: Option<usize>,
    /// `E/(1 − ν²)` [Pa].
    pub plane_strain_pa: f64,
    /// Mass [kg]; infinite for fixed bodies and the ground.
    pub mass_kg: f64,
    /// Hertz radius of curvature [m]; infinite for the ground.
    pub radius_m: f64,
    /// Coulomb friction coefficient (a pair uses the mean of both).
    pub friction: f64,
    /// Surface finish (sustained contact, [`crate::roughness`]).
    pub finish: SurfaceFinish,
}

/// One contact point with a non-zero impulse after a step.
#[derive(Clone, Debug)]
pub(crate) struct ContactPoint {
    /// Contact point on side 1, world frame [m].
    pub world_m: [f64; 3],
    /// Contact point in each body's (mesh) frame [m].
    pub local_m: [[f64; 3]; 2],
    /// Impulse applied to side 1 during the step, world frame [N·s]
    /// (side 2 receives the opposite).
    pub impulse_on_1: [f64; 3],
    /// Normal part of the impulse, ≥ 0 [N·s].
    pub normal_impulse: f64,
    /// Signed separation at the start of the step [m].
    pub separation_m: f64,
    /// Normal approach speed at the start of the step [m/s] (> 0 closing).
    pub approach_m_s: f64,
}

/// The touching points between two colliders after one step.
#[derive(Clone, Debug)]
pub(crate) struct PairContacts {
    /// Stable key of the collider pair.
    pub key: (u32, u32),
    /// Side indices into [`World::sides`].
    pub sides: [usize; 2],
    /// Unit contact normal from side 1 to side 2, world frame.
    pub normal: [f64; 3],
    /// Points with an impulse.
    pub points: Vec<ContactPoint>,
    /// How long before this step's start a body of the pair reached the
    /// contact, swept there by continuous collision detection in the step
    /// before [s] (0 for other contacts; [`World::swept_arrival_lag`]).
    pub swept_lag_s: f64,
}

/// A body's linear velocity [m/s], angular velocity [rad/s] and centre of
/// mass [m], world frame.
type BodyState = ([f64; 3], [f64; 3], [f64; 3]);

/// The rapier world plus the bookkeeping that maps colliders to objects.
pub(crate) struct World {
    world: PhysicsWorld,
    /// Per object: its body.
    bodies: Vec<RigidBodyHandle>,
    /// Contact sides: objects `0..n`, then the ground at index `n` if any.
    pub sides: Vec<ContactSide>,
    /// Pre-step velocity state of each object.
    pre_step: Vec<BodyState>,
    /// The same one step earlier, with whether the body was fast in that step
    /// (swept by CCD); `None` before the second step.
    step_before: Option<Vec<(BodyState, bool)>>,
    /// Per object: fast (swept) in the step just taken.
    fast: Vec<bool>,
    /// Whether a step was taken.
    stepped: bool,
    /// Per object: rolling-resistance lever arm [m].
    rolling_m: Vec<f64>,
    /// Per object: the centre of mass of a fixed body (its scene position), which
    /// rapier does not know: a fixed body carries no mass properties, so its
    /// `center_of_mass` is the mesh frame's origin (a generated box's corner).
    fixed_com: Vec<Option<[f64; 3]>>,
    /// Per object: scratch, normal impulse of the last step [N·s].
    normal_ns: Vec<f64>,
    /// Per object: thinnest extent of its collider (rapier's CCD thickness) [m].
    ccd_thickness_m: Vec<f32>,
    gravity: [f64; 3],
    /// Objects set on each other at the start (upper, lower), lifted apart
    /// by [`START_GAP_M`] ([`open_start_gaps`]).
    pub placed_pairs: Vec<(usize, usize)>,
}

fn v3(a: [f64; 3]) -> Vector {
    Vector::new(a[0] as f32, a[1] as f32, a[2] as f32)
}

fn d3(v: Vector) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Rotates `v` by the unit quaternion `q = [w, x, y, z]`.
pub(crate) fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let u = [q[1], q[2], q[3]];
    let t = cross(u, v).map(|x| 2.0 * x);
    let c = cross(u, t);
    [v[0] + q[0] * t[0] + c[0], v[1] + q[0] * t[1] + c[1], v[2] + q[0] * t[2] + c[2]]
}

/// Default Hertz radius: half the smallest bounding-box extent of the surface.
fn default_contact_radius(bank: &ModeBank) -> f64 {
    let (lo, hi) = bank.surface.bounding_box();
    (0..3).map(|c| hi[c] - lo[c]).fold(f64::INFINITY, f64::min).max(1e-6) * 0.5
}

/// World position of every surface node of object `i` at its initial pose.
pub(crate) fn initial_surface(scene: &Scene, i: usize, bank: &ModeBank) -> Vec<[f64; 3]> {
    let o = &scene.objects[i];
    let q = o.rotation.quaternion();
    let com = bank.mass.center_of_mass_m;
    bank.surface
        .positions
        .iter()
        .map(|p| {
            let r = rotate(q, sub(*p, com));
            [r[0] + o.position_m[0], r[1] + o.position_m[1], r[2] + o.position_m[2]]
        })
        .collect()
}

/// Rejects objects that start below the ground plane.
pub(crate) fn check_ground_clearance(scene: &Scene, banks: &[Arc<ModeBank>]) -> Result<(), SceneError> {
    let Some(ground) = &scene.ground else { return Ok(()) };
    for (i, bank) in banks.iter().enumerate() {
        let lowest = initial_surface(scene, i, bank).iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let depth = ground.height_m - lowest;
        if depth > 1e-6 {
            return Err(SceneError::invalid(
                format!("objects[{i}].position"),
                format!(
                    "object '{}' intersects the ground: its lowest point is {:.4} m below y = {}",
                    scene.object_name(i),
                    depth,
                    ground.height_m
                ),
            ));
        }
    }
    Ok(())
}

/// Two objects whose colliders overlap by more than this at the start are refused [m]:
/// rapier would push them apart at once (an impact out of nothing) or leave them
/// interlocked, silently (a box set 2 mm into another stayed 1.6 mm inside).
pub const START_OVERLAP_TOLERANCE_M: f64 = 1e-4;

/// Rejects two objects (not both fixed) whose colliders overlap at the start, as
/// [`check_ground_clearance`] does for the ground. Pairs parry cannot query are skipped.
fn check_overlaps(world: &PhysicsWorld, bodies: &[RigidBodyHandle], scene: &Scene) -> Result<(), SceneError> {
    // Each collider with its bounding box, computed once (a fine hull's box reads every vertex).
    let colliders: Vec<Vec<(&Collider, Aabb)>> = bodies
        .iter()
        .map(|b| {
            world.bodies[*b]
                .colliders()
                .iter()
                .map(|h| &world.colliders[*h])
                .map(|c| (c, c.compute_aabb()))
                .collect()
        })
        .collect();
    let fixed = |i: usize| !world.bodies[bodies[i]].is_dynamic();
    for i in 0..bodies.len() {
        for j in (i + 1..bodies.len()).filter(|&j| !(fixed(i) && fixed(j))) {
            let pairs = colliders[i].iter().flat_map(|a| colliders[j].iter().map(move |b| (a, b)));
            for ((a, a_box), (b, b_box)) in pairs {
                if !a_box.intersects(b_box) {
                    continue;
                }
                let contact =
                    rapier3d::parry::query::contact(a.position(), a.shape(), b.position(), b.shape(), 0.0);
                let depth = match contact {
                    Ok(Some(contact)) => -contact.dist as f64,
                    _ => 0.0,
                };
                // The query misreads shapes whose flat faces coincide (an exact
                // duplicate, a "+" of bars through each other: depth 0): a centre
                // of mass inside the other collider is an overlap whatever it says.
                let centres = [(&scene.objects[i].position_m, a, b), (&scene.objects[j].position_m, b, a)];
                let depth = centres
                    .iter()
                    .filter(|(_, own, _)| is_one_convex_piece(own))
                    .map(|(c, _, other)| centre_depth(c, other))
                    .fold(depth, f64::max);
                if depth > START_OVERLAP_TOLERANCE_M {
                    return Err(SceneError::invalid(
                        format!("objects[{j}].position"),
                        format!(
                            "object '{}' overlaps object '{}' by {:.4} m at the start (a dynamic body collides \
                             as its convex hull unless collider = \"decomposition\"): move them apart",
                            scene.object_name(j),
                            scene.object_name(i),
                            depth
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// A dynamic body set closer than this to a body below it (touching, or
/// overlapping within [`START_OVERLAP_TOLERANCE_M`]) is lifted to this gap
/// before the first step [m] (module doc, "Bodies set touching").
pub const START_GAP_M: f64 = 5e-5;

/// Lifts each dynamic body that starts within [`START_GAP_M`] of a body whose
/// centre of mass (the scene's `position`: rapier puts a fixed body's at its
/// mesh origin) lies lower, against gravity (+y without gravity), to that
/// gap, lowest bodies first, so a stack opens from the bottom up. Colliders
/// sit at their body's pose (no offset), so the body's pose is the collider's.
/// Returns the pairs of objects so set on each other (upper, lower).
fn open_start_gaps(
    world: &mut PhysicsWorld,
    bodies: &[RigidBodyHandle],
    scene: &Scene,
) -> Vec<(usize, usize)> {
    let mut placed = Vec::new();
    let gravity = scene.gravity_m_s2;
    let g = dot(gravity, gravity).sqrt();
    let up = if g > 0.0 { gravity.map(|x| -x / g) } else { [0.0, 1.0, 0.0] };
    let height: Vec<f64> = scene.objects.iter().map(|o| dot(o.position_m, up)).collect();
    let mut order: Vec<usize> = (0..bodies.len()).filter(|&i| world.bodies[bodies[i]].is_dynamic()).collect();
    order.sort_by(|&a, &b| height[a].total_cmp(&height[b]).then(a.cmp(&b)));
    for i in order {
        let mut nearest = f64::INFINITY;
        for (j, other) in bodies.iter().enumerate() {
            if j == i || height[j] >= height[i] {
                continue;
            }
            let mut touching = false;
            for a in world.bodies[bodies[i]].colliders() {
                for b in world.bodies[*other].colliders() {
                    let (a, b) = (&world.colliders[*a], &world.colliders[*b]);
                    let (pa, pb) = (world.bodies[bodies[i]].position(), world.bodies[*other].position());
                    if let Ok(Some(c)) =
                        rapier3d::parry::query::contact(pa, a.shape(), pb, b.shape(), START_GAP_M as f32)
                    {
                        nearest = nearest.min(c.dist as f64);
                        touching |= (c.dist as f64) < START_GAP_M;
                    }
                }
            }
            if touching {
                placed.push((i, j));
            }
        }
        if nearest < START_GAP_M {
            let lift = START_GAP_M - nearest;
            let body = &mut world.bodies[bodies[i]];
            let t = d3(body.translation());
            body.set_translation(v3([t[0] + lift * up[0], t[1] + lift * up[1], t[2] + lift * up[2]]), false);
        }
    }
    placed
}

/// How deep the point `p` (world frame) lies inside `collider`'s solid [m], 0
/// outside. Convex parts are measured against their faces: parry's projection
/// of a point inside a polyhedron returns the point itself.
fn centre_depth(p: &[f64; 3], collider: &Collider) -> f64 {
    let local = collider.position().inverse_transform_point(v3(*p));
    let shape = collider.shape();
    if let Some(hull) = shape.as_shape::<FaceHull>() {
        return hull.depth_of(local).max(0.0) as f64;
    }
    if let Some(compound) = shape.as_compound() {
        let part_depth = |(pose, part): &(Pose, SharedShape)| {
            let q = pose.inverse_transform_point(local);
            if let Some(hull) = part.as_shape::<FaceHull>() {
                hull.depth_of(q)
            } else if let Some(ball) = part.as_ball() {
                ball.radius - q.length()
            } else {
                0.0
            }
        };
        return compound.shapes().iter().map(part_depth).fold(0.0f32, f32::max) as f64;
    }
    let projection = shape.project_local_point(local, false);
    if projection.is_inside {
        (projection.point - local).length() as f64
    } else {
        0.0
    }
}

/// Whether `collider` is one convex piece, whose body's centre of mass then
/// lies inside it (a decomposed bowl's centre may lie in its open cavity).
fn is_one_convex_piece(collider: &Collider) -> bool {
    let shape = collider.shape();
    shape.as_shape::<FaceHull>().is_some() || shape.as_compound().is_some_and(|c| c.shapes().len() == 1)
}

impl World {
    /// Builds bodies and colliders for all objects and the ground.
    pub fn new(scene: &Scene, banks: &[Arc<ModeBank>]) -> Result<World, SceneError> {
        let mut world = PhysicsWorld::new();
        world.gravity = v3(scene.gravity_m_s2);
        world.integration_parameters.dt = (1.0 / scene.physics_rate_hz) as f32;
        world.integration_parameters.friction_model = FrictionModel::Coulomb;
        world.integration_parameters.normalized_prediction_distance =
            (scene.contact_prediction_m / world.integration_parameters.length_unit as f64) as f32;
        let mut bodies = Vec::with_capacity(banks.len());
        let mut sides = Vec::with_capacity(banks.len() + 1);
        let mut ccd_thickness_m = Vec::with_capacity(banks.len());
        let mut shapes = ShapeCache::default();
        for (i, bank) in banks.iter().enumerate() {
            let (handle, side) = add_object(&mut world, &mut shapes, scene, i, bank)?;
            let thinnest =
                world.bodies[handle].colliders().iter().map(|c| world.colliders[*c].shape().ccd_thickness());
            ccd_thickness_m.push(thinnest.fold(f32::INFINITY, f32::min));
            bodies.push(handle);
            sides.push(side);
        }
        if let Some(g) = &scene.ground {
            let material: Material =
                resolve_material(&g.material).map_err(|m| SceneError::invalid("ground.material", m))?;
            let body = world.bodies.insert(RigidBodyBuilder::fixed().translation(v3([0.0, g.height_m, 0.0])));
            let collider = ColliderBuilder::halfspace(rapier3d::na::Unit::new_unchecked(Vector::Y))
                .friction(g.friction as f32)
                .restitution(g.restitution as f32)
                .friction_combine_rule(CoefficientCombineRule::Average)
                .restitution_combine_rule(CoefficientCombineRule::Average)
                .user_data(GROUND);
            world.colliders.insert_with_parent(collider, body, &mut world.bodies);
            let finish = resolve_surface(g.surface.as_ref(), &g.material)
                .map_err(|(key, m)| SceneError::invalid(format!("ground.surface.{key}"), m))?;
            sides.push(ContactSide {
                object: None,
                plane_strain_pa: plane_strain_modulus(&material),
                mass_kg: f64::INFINITY,
                radius_m: f64::INFINITY,
                friction: g.friction,
                finish,
            });
        }
        let pre_step = vec![([0.0; 3], [0.0; 3], [0.0; 3]); bodies.len()];
        let n_objects = bodies.len();
        check_overlaps(&world, &bodies, scene)?;
        let placed_pairs = open_start_gaps(&mut world, &bodies, scene);
        let rolling_m = scene.objects.iter().map(|o| o.rolling_resistance_m).collect();
        let fixed_com =
            scene.objects.iter().map(|o| (o.body != BodyKind::Dynamic).then_some(o.position_m)).collect();
        let normal_ns = vec![0.0; bodies.len()];
        Ok(World {
            world,
            bodies,
            sides,
            pre_step,
            step_before: None,
            fast: vec![false; n_objects],
            stepped: false,
            rolling_m,
            fixed_com,
            normal_ns,
            ccd_thickness_m,
            gravity: scene.gravity_m_s2,
            placed_pairs,
        })
    }

    /// World position of object `i`'s centre of mass [m].
    pub fn center_of_mass(&self, i: usize) -> [f64; 3] {
        self.fixed_com[i].unwrap_or_else(|| d3(self.world.bodies[self.bodies[i]].center_of_mass()))
    }

    /// Rotates a world vector into object `i`'s mesh frame (current pose).
    pub fn to_body(&self, i: usize, v: [f64; 3]) -> [f64; 3] {
        let r = self.world.bodies[self.bodies[i]].rotation();
        let q = [r.w as f64, -r.x as f64, -r.y as f64, -r.z as f64];
        rotate(q, v)
    }

    /// The first object whose collider contains the world point `p`.
    pub fn object_containing(&self, p: [f64; 3]) -> Option<usize> {
        self.bodies.iter().position(|h| {
            self.world.bodies[*h].colliders().iter().any(|c| {
                let collider = &self.world.colliders[*c];
                collider.shape().contains_point(collider.position(), v3(p))
            })
        })
    }

    /// True when no dynamic body is awake.
    pub fn all_asleep(&self) -> bool {
        self.world.bodies.iter().all(|(_, b)| !b.is_dynamic() || b.is_sleeping())
    }

    /// Advances by one step.
    pub fn step(&mut self) {
        if self.stepped {
            self.step_before = Some(self.pre_step.iter().copied().zip(self.fast.iter().copied()).collect());
        }
        self.stepped = true;
        for (i, h) in self.bodies.iter().enumerate() {
            let b = &self.world.bodies[*h];
            self.pre_step[i] = (d3(b.linvel()), d3(b.angvel()), d3(b.center_of_mass()));
        }
        self.update_bullets();
        self.world.step();
    }

    /// Continuous collision detection (CCD) against other moving bodies for
    /// the bodies that are fast this step.
    ///
    /// Rapier sweeps every fast dynamic body (one whose farthest point moves
    /// more than half its thinnest extent in a step) against fixed geometry;
    /// only a "bullet" (`ccd_enabled`) also sweeps dynamic bodies, and a
    /// bullet never sweeps another bullet. Were every body a bullet, no two
    /// dynamic bodies would ever be swept against each other (a fast ball
    /// went through a decomposed bowl's wall, `tests/ccd.rs`). So a body is a
    /// bullet exactly while it moves faster than a quarter of its thinnest
    /// extent per step (before gravity acts, hence a margin below rapier's
    /// half): a fast body sweeps the slow ones, which are not bullets. Two
    /// fast bodies flying into each other still rely on contact prediction.
    fn update_bullets(&mut self) {
        let dt = self.world.integration_parameters.dt;
        for (i, (h, thickness)) in self.bodies.iter().zip(&self.ccd_thickness_m).enumerate() {
            let b = &self.world.bodies[*h];
            self.fast[i] = false;
            if !b.is_dynamic() || b.is_sleeping() {
                continue;
            }
            let reach = b.linvel().length() + b.angvel().length() * b.mass_properties().max_extent();
            let fast = reach * dt > 0.25 * thickness;
            self.fast[i] = fast;
            if fast != b.is_ccd_enabled() {
                self.world.bodies[*h].enable_ccd(fast);
            }
        }
    }

    /// Every contact point that carried an impulse in the last step, pairs in
    /// the narrow phase's (deterministic) order.
    pub fn contacts(&self, out: &mut Vec<PairContacts>) {
        out.clear();
        let dt = self.world.integration_parameters.dt as f64;
        for pair in self.world.narrow_phase.contact_pairs() {
            let (Some(c1), Some(c2)) =
                (self.world.colliders.get(pair.collider1), self.world.colliders.get(pair.collider2))
            else {
                continue;
            };
            let sides = [self.side_of(c1.user_data), self.side_of(c2.user_data)];
            let mut points = Vec::new();
            let mut normal = [0.0; 3];
            for m in pair.solver_manifolds() {
                let n = d3(m.data.normal);
                // A manifold's points are in its subshape's frame: a compound's
                // part (the exact ball or cylinder, placed and turned in the
                // body) has its own. Taken as the collider's, a rod's contacts
                // lay 5 cm off its surface and every strike was dropped.
                let in_collider = |sub: Option<&Pose>, p: Vector| sub.map_or(p, |s| s.transform_point(p));
                let (sub1, sub2) = (m.subshape_pos1(), m.subshape_pos2());
                for p in &m.points {
                    let jn = p.data.impulse as f64;
                    if jn <= 0.0 || !jn.is_finite() {
                        continue;
                    }
                    let (local1, local2) = (in_collider(sub1, p.local_p1), in_collider(sub2, p.local_p2));
                    let world_m = d3(c1.position().transform_point(local1));
                    let friction = friction_world(&p.data, n);
                    // The solver pushes body 1 away from body 2, i.e. along −n.
                    let impulse_on_1 =
                        [-jn * n[0] + friction[0], -jn * n[1] + friction[1], -jn * n[2] + friction[2]];
                    let approach = self.approach_speed(sides, world_m, n, dt);
                    for c in 0..3 {
                        normal[c] += jn * n[c];
                    }
                    points.push(ContactPoint {
                        world_m,
                        local_m: [d3(local1), d3(local2)],
                        impulse_on_1,
                        normal_impulse: jn,
                        separation_m: p.dist as f64,
                        approach_m_s: approach,
                    });
                }
            }
            if !points.is_empty() {
                let key = (pair.collider1.into_raw_parts().0, pair.collider2.into_raw_parts().0);
                let length = dot(normal, normal).sqrt();
                let normal = if length > 0.0 { normal.map(|x| x / length) } else { [0.0, 1.0, 0.0] };
                let swept_lag_s = sides.iter().map(|&s| self.swept_arrival_lag(s, dt)).fold(0.0, f64::max);
                out.push(PairContacts { key, sides, normal, points, swept_lag_s });
            }
        }
    }

    /// How long before the start of the last step contact side `side`'s body
    /// stopped short, swept by CCD [s]. Rapier's CCD stops a fast body at its
    /// time of impact and drops the rest of that step's motion, and the
    /// bounce comes in the next step: timed at that step's start, an impact
    /// was up to one step late (16 ms at `physics_rate = 60`). The motion
    /// lost, `(v·dt + g·dt²/2) − Δx` over the step before, divided by the
    /// speed, is how long the body waited at the contact. 0 unless the body
    /// was fast (swept) in that step.
    pub fn swept_arrival_lag(&self, side: usize, dt: f64) -> f64 {
        let (Some(i), Some(before)) = (self.sides.get(side).and_then(|s| s.object), &self.step_before) else {
            return 0.0;
        };
        let ((v, _, c0), fast) = before[i];
        if !fast || !self.sides[side].mass_kg.is_finite() {
            return 0.0;
        }
        let c1 = self.pre_step[i].2;
        let expected = [0, 1, 2].map(|k| v[k] * dt + 0.5 * self.gravity[k] * dt * dt);
        let lost = sub(expected, sub(c1, c0));
        let speed = dot(v, v).sqrt();
        if speed > 0.0 {
            (dot(lost, lost).sqrt() / speed).min(dt)
        } else {
            0.0
        }
    }

    /// Applies the rolling-resistance couple (module doc) for the contacts
    /// `pairs` of the last step.
    pub fn resist_rolling(&mut self, pairs: &[PairContacts]) {
        self.normal_ns.iter_mut().for_each(|x| *x = 0.0);
        for pair in pairs {
            let jn: f64 = pair.points.iter().map(|p| p.normal_impulse).sum();
            for side in pair.sides {
                if let Some(i) = self.sides[side].object {
                    self.normal_ns[i] += jn;
                }
            }
        }
        let dt = self.world.integration_parameters.dt as f64;
        let g = dot(self.gravity, self.gravity).sqrt();
        for (i, h) in self.bodies.iter().enumerate() {
            let load = ROLLING_LOAD_CAP * self.sides[i].mass_kg * g * dt;
            let (jn, b) = (self.normal_ns[i].min(load), self.rolling_m[i]);
            let body = &mut self.world.bodies[*h];
            if jn <= 0.0 || b <= 0.0 || !body.is_dynamic() || body.is_sleeping() {
                continue;
            }
            let w = d3(body.angvel());
            let speed = dot(w, w).sqrt();
            if !(speed > 0.0 && speed.is_finite()) {
                continue;
            }
            let axis = w.map(|x| x / speed);
            let inv = body.mass_properties().effective_world_inv_inertia * v3(axis);
            let k = dot(axis, d3(inv));
            if !(k > 0.0 && k.is_finite()) {
                continue;
            }
            let couple = (b * jn).min(speed / k);
            body.apply_torque_impulse(v3(axis.map(|x| -couple * x)), false);
        }
    }

    /// Linear velocity, angular velocity and centre of mass (world frame)
    /// of a contact side's body now; `None` for the ground and fixed bodies.
    pub fn kinematics(&self, side: usize) -> Option<([f64; 3], [f64; 3], [f64; 3])> {
        let i = self.sides.get(side)?.object?;
        let b = &self.world.bodies[self.bodies[i]];
        b.is_dynamic().then(|| (d3(b.linvel()), d3(b.angvel()), d3(b.center_of_mass())))
    }

    fn side_of(&self, user_data: u128) -> usize {
        if user_data == GROUND {
            self.sides.len() - 1
        } else {
            user_data as usize
        }
    }

    /// Closing speed along `n` (from side 1 to side 2) at `p`, from the
    /// velocities at the start of the step advanced by half a step of gravity.
    fn approach_speed(&self, sides: [usize; 2], p: [f64; 3], n: [f64; 3], dt: f64) -> f64 {
        let velocity = |side: usize| -> [f64; 3] {
            let Some(i) = self.sides[side].object else { return [0.0; 3] };
            if !self.sides[side].mass_kg.is_finite() {
                return [0.0; 3];
            }
            let (v, w, c) = self.pre_step[i];
            let r = cross(w, sub(p, c));
            let g = self.gravity.map(|x| 0.5 * dt * x);
            [v[0] + r[0] + g[0], v[1] + r[1] + g[1], v[2] + r[2] + g[2]]
        };
        let rel = sub(velocity(sides[1]), velocity(sides[0]));
        (-dot(rel, n)).max(0.0)
    }
}

/// World friction impulse on body 1 from the solver's tangent impulse.
///
/// The solver reports the step's total tangent impulse `T` in a tangent basis
/// it does not expose, plus the last sub-step's impulse `w` both in that basis
/// and as a world vector `W = w₁ t₁ + w₂ t₂`. Reading the tangent plane as the
/// complex plane with `t₂ = n × t₁`, `W = w·t₁`, so the world total is
/// `(T / w) · W`: `W` rotated by `arg T − arg w` about `n` and scaled by |T|/|w|.
fn friction_world(data: &ContactData, n: [f64; 3]) -> [f64; 3] {
    let t = (data.tangent_impulse.x as f64, data.tangent_impulse.y as f64);
    let w = (data.warmstart_tangent_impulse.x as f64, data.warmstart_tangent_impulse.y as f64);
    let ww = d3(data.warmstart_tangent_world);
    let w2 = w.0 * w.0 + w.1 * w.1;
    if w2 < 1e-30 || !(t.0.is_finite() && t.1.is_finite()) {
        return [0.0; 3];
    }
    // z = T / w as a complex number.
    let z = ((t.0 * w.0 + t.1 * w.1) / w2, (t.1 * w.0 - t.0 * w.1) / w2);
    let nw = cross(n, ww);
    [z.0 * ww[0] + z.1 * nw[0], z.0 * ww[1] + z.1 * nw[1], z.0 * ww[2] + z.1 * nw[2]]
}

fn add_object(
    world: &mut PhysicsWorld,
    shapes: &mut ShapeCache,
    scene: &Scene,
    i: usize,
    bank: &Arc<ModeBank>,
) -> Result<(RigidBodyHandle, ContactSide), SceneError> {
    let o = &scene.objects[i];
    let path = format!("objects[{i}]");
    let q = o.rotation.quaternion();
    let com = bank.mass.center_of_mass_m;
    let rc = rotate(q, com);
    let origin = [o.position_m[0] - rc[0], o.position_m[1] - rc[1], o.position_m[2] - rc[2]];
    let rotation = Rotation::from_xyzw(q[1] as f32, q[2] as f32, q[3] as f32, q[0] as f32).normalize();
    let pose = Pose::from_parts(v3(origin), rotation);
    let material = &bank.material;
    let dynamic = o.body == BodyKind::Dynamic;
    let builder = if dynamic {
        let inertia = bank.mass.inertia_kg_m2;
        let m = Matrix::from_cols_array_2d(&inertia.map(|r| r.map(|x| x as f32)));
        let props = MassProperties::with_inertia_matrix(v3(com), bank.mass.mass_kg as f32, m);
        RigidBodyBuilder::dynamic()
            .pose(pose)
            .linvel(v3(o.linear_velocity_m_s))
            .angvel(v3(o.angular_velocity_rad_s))
            .additional_mass_properties(props)
    } else {
        RigidBodyBuilder::fixed().pose(pose)
    };
    let collider = if dynamic {
        ColliderBuilder::new(shapes.dynamic_shape(bank, o.collider, &path)?)
    } else if let Some(convex) = shapes.fixed_convex_shape(bank, &path)? {
        ColliderBuilder::new(convex)
    } else {
        // Internal edges fixed: a ball rolling across a triangle boundary of a
        // flat face must not hit the edge (a ghost collision, heard as a tick).
        ColliderBuilder::trimesh_with_flags(
            surface_points(bank),
            surface_triangles(bank),
            TriMeshFlags::FIX_INTERNAL_EDGES,
        )
        .map_err(|e| SceneError::Collider { path: path.clone(), message: format!("{e:?}") })?
    };
    let collider = collider
        .density(0.0)
        .friction(o.friction as f32)
        .restitution(o.restitution as f32)
        .friction_combine_rule(CoefficientCombineRule::Average)
        .restitution_combine_rule(CoefficientCombineRule::Average)
        .user_data(i as u128);
    let handle = world.bodies.insert(builder);
    let activation = world.bodies[handle].activation_mut();
    activation.time_until_sleep = SLEEP_AFTER_S as f32;
    // rapier compares half the farthest point's displacement per step with
    // this threshold × dt, so the point speed limit is twice the threshold.
    activation.normalized_linear_threshold =
        (0.5 * SLEEP_SPEED_M_S) as f32 / world.integration_parameters.length_unit;
    world.colliders.insert_with_parent(collider, handle, &mut world.bodies);
    // rapier derives the world centre of mass and the extent from the mass
    // properties at the first step; before it, `center_of_mass()` is the mesh
    // origin (a generated box's corner), and the first step's approach speeds
    // would be taken about it (a box set tipping on its edge "struck" the
    // floor at 0.05–0.07 m/s at t = 0).
    world.bodies[handle].recompute_mass_properties_from_colliders(&world.colliders);
    let side = ContactSide {
        object: Some(i),
        plane_strain_pa: plane_strain_modulus(material),
        mass_kg: if dynamic { bank.mass.mass_kg } else { f64::INFINITY },
        radius_m: o.contact_radius_m.unwrap_or_else(|| default_contact_radius(bank)),
        friction: o.friction,
        finish: object_surface(o, bank)
            .map_err(|(key, m)| SceneError::invalid(format!("{path}.surface.{key}"), m))?,
    };
    Ok((handle, side))
}
