//! A frame's sprite instances on the CPU (paper §5, §6.1, §3.3): every
//! sprite's four corners (camera-facing, flat for cirrus, or locked while
//! the camera is inside it), shaded per corner by
//! [`crate::methods::sprites::model::shading`] × formation alpha × facing fade, then
//! all sprites of all clouds sorted back to front.
//!
//! The scene's own clouds (`[[sprite_clouds]]`, `[[layers]]`) keep their
//! shaded corners between frames and are re-shaded only when the cache of
//! §6.1 says so (camera move or time past thresholds that grow with
//! distance, [`ShadeCacheConfig`]) or the sun moved; physics clouds move
//! every step and are shaded every frame, their formation following the
//! parcel's condensed fill. A parcel's sprites are seeded by its stable id
//! ([`CloudParcel::id`]), so a parcel that condenses or evaporates leaves
//! every other parcel's sprites where they were.

use glam::{Vec3, Vec4};

use super::SpriteInstance;
use crate::methods::sprites::model::atlas::Atlas;
use crate::methods::sprites::model::facing::Facing;
use crate::methods::sprites::model::formation::formation_alpha;
use crate::methods::sprites::model::impostor::{
    SECTORS, ShadeCacheConfig, ShadeStamp, block_faces, block_of, span_in_impostors,
};
use crate::methods::sprites::model::shading::{Lighting, group_centers};
use crate::methods::sprites::model::vertices::corners;
use crate::methods::sprites::model::{SpriteCloud, parcel_clouds};
use crate::physics::CloudParcel;

/// Sun moves smaller than this re-use the cached shading (0.5°, the
/// cache's own turn threshold).
const SUN_COS: f32 = 0.999_962;

/// The local hour the time-of-day tables are read at, from the sun's
/// direction alone: the hour at which an equinox sun on the equator stands
/// at the same elevation (sin e = cos H), before noon when the sun is east
/// (+x) of the meridian. Elevation 0 is 06:00 or 18:00, the zenith 12:00,
/// so dawn and dusk colours follow the program's clock through its sun,
/// for scenes with a `[sun]` clock and with a pinned sun alike.
pub fn equivalent_hour(sun_dir: Vec3) -> f32 {
    let d = sun_dir.normalize_or(Vec3::Z);
    let hours_from_noon = d.z.clamp(-1.0, 1.0).acos().to_degrees() / 15.0;
    if d.x >= 0.0 {
        12.0 - hours_from_noon
    } else {
        12.0 + hours_from_noon
    }
}

/// The shading's lighting for a frame's sun (direction and equivalent hour).
pub fn lighting(sun_dir: Vec3) -> Lighting {
    // A sun direction is a unit vector by construction; Lighting::new only
    // fails on a zero or non-finite one, which then means "straight up".
    Lighting::new(sun_dir, equivalent_hour(sun_dir))
        .unwrap_or_else(|_| Lighting::new(Vec3::Z, 12.0).expect("a valid default"))
}

/// Appends the shaded instances of `cloud` at formation `progress`; with
/// `facing`, sprites lock their facing inside half their radius (§3.3).
pub fn shade(
    cloud: &SpriteCloud,
    lighting: &Lighting,
    camera_m: Vec3,
    progress: f32,
    mut facing: Option<&mut [Facing]>,
    out: &mut Vec<SpriteInstance>,
) {
    let groups = group_centers(&cloud.sprites);
    let radius = cloud.radius_m.max(1e-3);
    for (i, s) in cloud.sprites.iter().enumerate() {
        let g = groups[s.group as usize];
        let views = if cloud.kind.is_flat() {
            [(Vec3::Z, 1.0), (Vec3::Z, 0.0)]
        } else if let Some(f) = facing.as_deref_mut() {
            f[i].update(s.center_m, 0.5 * s.width_m.max(s.height_m), camera_m)
        } else {
            let n = (camera_m - s.center_m).try_normalize().unwrap_or(Vec3::Z);
            [(n, 1.0), (n, 0.0)]
        };
        let radial = (s.center_m - cloud.center_m).length() / radius;
        let formed = formation_alpha(progress, radial);
        for (normal, fade) in views {
            let alpha = formed * fade;
            if alpha <= 0.0 {
                continue;
            }
            let c = corners(s.center_m, normal, s.width_m, s.height_m, s.rotation_rad);
            let shade = c.map(|p| cloud.vertex_shade(lighting, s, g, p, alpha));
            out.push(SpriteInstance {
                corners: c.map(|p| p.extend(1.0).to_array()),
                colors: shade.map(|v| v.painted.to_array()),
                sun: shade.map(|v| v.sun),
                sky: shade.map(|v| v.sky),
                uv: Atlas::uv_rect(s.texture),
            });
        }
    }
}

/// Indices of `instances` from farthest to nearest to `camera_m` (sprite
/// centre = mean of two opposite corners; ties keep their order).
pub fn back_to_front(instances: &[SpriteInstance], camera_m: Vec3) -> Vec<u32> {
    let mut keyed: Vec<(f32, u32)> = instances
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let c = 0.5 * (Vec4::from(s.corners[0]) + Vec4::from(s.corners[2])).truncate();
            (c.distance_squared(camera_m), i as u32)
        })
        .collect();
    keyed.sort_by(|a, b| b.0.total_cmp(&a.0));
    keyed.into_iter().map(|(_, i)| i).collect()
}

struct Cached {
    stamp: ShadeStamp,
    instances: Vec<SpriteInstance>,
}

/// What the last frame built.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SpriteStats {
    /// Sprites drawn.
    pub sprites: usize,
    /// Scene clouds re-shaded this frame (the rest came from the cache).
    pub reshaded: usize,
    /// Physics parcels drawn as sprite clouds.
    pub parcel_clouds: usize,
    /// Time to shade and sort. units: ms
    pub build_ms: f64,
}

/// A condensed parcel drawn as a sprite cloud.
#[derive(Clone)]
struct ParcelCloud {
    /// [`CloudParcel::id`].
    id: u64,
    /// Its fill: the formation progress (Listing 1).
    fill: f32,
    cloud: SpriteCloud,
    span: (f32, f32),
}

/// The scene's sprite clouds and their per-sprite state between frames.
#[derive(Default)]
pub struct SpriteScene {
    clouds: Vec<SpriteCloud>,
    facing: Vec<Vec<Facing>>,
    cache: Vec<Option<Cached>>,
    cache_cfg: ShadeCacheConfig,
    sun_dir: Vec3,
    pub stats: SpriteStats,
    /// The impostor ring's (centre, radius): the clouds it holds
    /// ([`span_in_impostors`]) are left out of [`SpriteScene::frame`].
    pub impostored: Option<(Vec3, f32)>,
    /// Each cloud's sprites' (bottom, top). units: m
    spans: Vec<(f32, f32)>,
    /// The parcels of the last frame and their sprite clouds (rebuilt
    /// only when the parcels change).
    parcels_in: Vec<CloudParcel>,
    parcels: Vec<ParcelCloud>,
    /// The sun their sunlit shares are for.
    parcels_sun: Vec3,
    /// Physics clouds of the ring set being rendered (taken at its first
    /// face, so its 8 faces show one state of the field) and the ids of
    /// those in the newest complete set (left out of the direct draw).
    ring_building: Vec<ParcelCloud>,
    ring_ids: std::collections::BTreeSet<u64>,
}

/// (bottom, top) of a cloud's sprites. units: m
fn z_span(cloud: &SpriteCloud) -> (f32, f32) {
    cloud
        .sprites
        .iter()
        .fold((f32::MAX, f32::MIN), |(lo, hi), s| {
            let h = 0.5 * s.height_m.max(s.width_m);
            (lo.min(s.center_m.z - h), hi.max(s.center_m.z + h))
        })
}

impl SpriteScene {
    /// The scene's clouds (from [`crate::scene::SceneProfile::build_sprite_clouds`]).
    pub fn new(clouds: Vec<SpriteCloud>) -> Self {
        let facing = clouds
            .iter()
            .map(|c| vec![Facing::default(); c.sprites.len()])
            .collect();
        let cache = clouds.iter().map(|_| None).collect();
        let spans = clouds.iter().map(z_span).collect();
        Self {
            spans,
            clouds,
            facing,
            cache,
            ..Self::default()
        }
    }

    /// Whether the scene authored any sprite cloud.
    pub fn is_empty(&self) -> bool {
        self.clouds.iter().all(|c| c.sprites.is_empty())
    }

    /// The scene's clouds.
    pub fn clouds(&self) -> &[SpriteCloud] {
        &self.clouds
    }

    /// Every sprite of the frame, back to front: the scene's clouds (from
    /// the cache where it holds) and, for the sprites method, `parcels` as
    /// sprite clouds (seeded by their id, formed as far as their fill).
    pub fn frame(
        &mut self,
        parcels: &[CloudParcel],
        sun_dir: Vec3,
        camera_m: Vec3,
        time_s: f32,
    ) -> Vec<SpriteInstance> {
        let start = std::time::Instant::now();
        let light = lighting(sun_dir);
        if sun_dir.dot(self.sun_dir) < SUN_COS {
            self.cache.iter_mut().for_each(|c| *c = None);
            self.sun_dir = sun_dir;
        }
        let mut all = Vec::new();
        let mut reshaded = 0;
        for (i, cloud) in self.clouds.iter().enumerate() {
            if let Some((at, r)) = self.impostored
                && span_in_impostors(at, r, cloud.center_m, self.spans[i])
            {
                continue;
            }
            let stale = self.cache[i].as_ref().is_none_or(|c| {
                self.cache_cfg.stale_within(
                    c.stamp,
                    time_s,
                    camera_m,
                    cloud.center_m,
                    cloud.radius_m,
                    false,
                )
            });
            if stale {
                let mut instances = Vec::with_capacity(cloud.sprites.len());
                shade(
                    cloud,
                    &light,
                    camera_m,
                    1.0,
                    Some(&mut self.facing[i]),
                    &mut instances,
                );
                self.cache[i] = Some(Cached {
                    stamp: ShadeStamp { time_s, camera_m },
                    instances,
                });
                reshaded += 1;
            }
            all.extend_from_slice(&self.cache[i].as_ref().expect("filled above").instances);
        }
        self.set_parcels(parcels, sun_dir);
        let ring = self.impostored.is_some();
        let mut parcel_clouds = 0;
        for p in &self.parcels {
            if ring && self.ring_ids.contains(&p.id) {
                continue;
            }
            // Placed as a full cloud, faded in by its fill: the sprite
            // layout does not change (pop) as the fill moves, only the
            // formation alpha does.
            shade(&p.cloud, &light, camera_m, p.fill, None, &mut all);
            parcel_clouds += 1;
        }
        let order = back_to_front(&all, camera_m);
        let sorted: Vec<SpriteInstance> = order.iter().map(|&i| all[i as usize]).collect();
        self.stats = SpriteStats {
            sprites: sorted.len(),
            reshaded,
            parcel_clouds,
            build_ms: start.elapsed().as_secs_f64() * 1e3,
        };
        sorted
    }

    /// Builds the sprite clouds of `parcels` (full clouds, seeded by their
    /// ids; formation follows the fill at draw time) with their sunlit
    /// shares under `sun_dir`, unless they are the last frame's parcels
    /// under a sun that has moved less than the scene's clouds' cache
    /// allows (`SUN_COS`).
    fn set_parcels(&mut self, parcels: &[CloudParcel], sun_dir: Vec3) {
        if parcels == self.parcels_in.as_slice() && sun_dir.dot(self.parcels_sun) >= SUN_COS {
            return;
        }
        self.parcels_in = parcels.to_vec();
        self.parcels_sun = sun_dir;
        let drawn: Vec<CloudParcel> = parcels
            .iter()
            .filter(|p| p.fill > 0.0 && p.radius_m.is_finite() && p.center_m.is_finite())
            .copied()
            .collect();
        self.parcels = drawn
            .iter()
            .zip(parcel_clouds(&drawn, sun_dir))
            .map(|(p, cloud)| ParcelCloud {
                id: p.id,
                fill: p.fill,
                span: z_span(&cloud),
                cloud,
            })
            .collect();
    }

    /// Ids of this frame's physics clouds that a ring at `ring_cam` with
    /// radius `radius_m` holds (same rules as the scene's clouds).
    fn ring_parcels(&self, ring_cam: Vec3, radius_m: f32) -> impl Iterator<Item = &ParcelCloud> {
        self.parcels
            .iter()
            .filter(move |p| span_in_impostors(ring_cam, radius_m, p.cloud.center_m, p.span))
    }

    /// A ring set starts at `ring_cam`: the physics clouds it will hold
    /// are taken now, shaded under `sun_dir`, for all 8 of its faces.
    pub fn ring_started(
        &mut self,
        parcels: &[CloudParcel],
        ring_cam: Vec3,
        radius_m: f32,
        sun_dir: Vec3,
    ) {
        self.set_parcels(parcels, sun_dir);
        self.ring_building = self.ring_parcels(ring_cam, radius_m).cloned().collect();
    }

    /// The set started by [`Self::ring_started`] is complete: its physics
    /// clouds leave the direct draw.
    pub fn ring_completed(&mut self) {
        self.ring_ids = self.ring_building.iter().map(|p| p.id).collect();
    }

    /// Whether the physics clouds a ring at `ring_cam` would hold now are
    /// not those of its newest set (one condensed or evaporated beyond
    /// the radius, or crossed it): the ring must be re-rendered. `sun_dir`:
    /// the frame's sun, which the parcels' sunlit shares are for.
    pub fn ring_changed(
        &mut self,
        parcels: &[CloudParcel],
        ring_cam: Vec3,
        radius_m: f32,
        sun_dir: Vec3,
    ) -> bool {
        self.set_parcels(parcels, sun_dir);
        !self
            .ring_parcels(ring_cam, radius_m)
            .map(|p| p.id)
            .eq(self.ring_ids.iter().copied())
    }

    /// The sprites of face `k` of an impostor ring centred at `ring_cam`
    /// with radius `radius_m`: the clouds the ring holds (the scene's, and
    /// the physics clouds taken by [`Self::ring_started`]) grouped into
    /// the paper's 16 km² blocks, every block whose square (grown by its
    /// clouds' reach) meets the face's 45° drawn whole
    /// ([`block_faces`]: a block across a face border goes into both
    /// faces and each face's projection cuts it at the shared edge),
    /// shaded facing `ring_cam`, back to front from `ring_cam`.
    pub fn face_instances(
        &self,
        ring_cam: Vec3,
        radius_m: f32,
        k: usize,
        sun_dir: Vec3,
    ) -> Vec<SpriteInstance> {
        debug_assert!(k < SECTORS);
        let light = lighting(sun_dir);
        // Block → (its clouds with their formation, its reach).
        type Block<'a> = (Vec<(&'a SpriteCloud, f32)>, f32);
        let mut blocks: std::collections::BTreeMap<(i32, i32), Block> = Default::default();
        let scene = self
            .clouds
            .iter()
            .zip(&self.spans)
            .filter(|(c, span)| span_in_impostors(ring_cam, radius_m, c.center_m, **span))
            .map(|(c, _)| (c, 1.0));
        let physics = self.ring_building.iter().map(|p| (&p.cloud, p.fill));
        for (cloud, progress) in scene.chain(physics) {
            let b = blocks.entry(block_of(cloud.center_m)).or_default();
            b.0.push((cloud, progress));
            b.1 = b.1.max(cloud.radius_m);
        }
        let mut all = Vec::new();
        for (b, (clouds, reach)) in &blocks {
            if block_faces(ring_cam, *b, *reach)[k] {
                for (cloud, progress) in clouds {
                    shade(cloud, &light, ring_cam, *progress, None, &mut all);
                }
            }
        }
        let order = back_to_front(&all, ring_cam);
        order.iter().map(|&i| all[i as usize]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::sprites::model::presets::CloudType;

    fn one_sprite_cloud() -> SpriteCloud {
        let mut c = CloudType::CumulusHumilis
            .spec("", 0.0, 0.0, 1000.0, 1)
            .build();
        c.sprites.truncate(1);
        c
    }

    #[test]
    fn facing_locks_inside_half_a_sprite_radius_and_fades_by_angle() {
        let cloud = one_sprite_cloud();
        let s = cloud.sprites[0];
        let half = 0.25 * s.width_m.max(s.height_m);
        let light = lighting(Vec3::new(0.3, 0.2, 0.9));
        let mut facing = vec![Facing::default()];
        let mut at = |cam: Vec3| {
            let mut out = Vec::new();
            shade(&cloud, &light, cam, 1.0, Some(&mut facing), &mut out);
            out
        };
        // Outside: the quad turns with the camera.
        let far_a = at(s.center_m + Vec3::new(0.0, -10.0 * half, 0.0));
        let far_b = at(s.center_m + Vec3::new(10.0 * half, 0.0, 0.0));
        assert_ne!(far_a[0].corners, far_b[0].corners);
        // Entering from the south: locked, then the same corners wherever
        // the camera goes inside, fading as it turns away from the lock.
        let enter = at(s.center_m + Vec3::new(0.0, -0.9 * half, 0.0));
        let side = at(s.center_m + Vec3::new(0.6 * half, -0.6 * half, 0.0));
        assert_eq!(enter[0].corners, side[0].corners);
        // |n·d| = cos 45° of the entering alpha.
        let ratio = side[0].colors[0][3] / enter[0].colors[0][3];
        assert!(
            (ratio - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-3,
            "{ratio}"
        );
        // Edge-on (camera in the locked plane): fully faded, not drawn.
        assert!(at(s.center_m + Vec3::new(0.9 * half, 0.0, 0.0)).is_empty());
        // Leaving (between half and the whole radius): the locked quad
        // fades out as the camera-facing one fades in; beyond, it faces
        // the camera again.
        let leaving = at(s.center_m + Vec3::new(0.0, 1.5 * half, 0.0));
        assert_eq!(leaving.len(), 2);
        assert_eq!(leaving[0].corners, enter[0].corners);
        let out = at(s.center_m + Vec3::new(10.0 * half, 0.0, 0.0));
        assert_eq!(out.len(), 1);
        assert_eq!(out[0].corners, far_b[0].corners);
    }

    #[test]
    fn sprites_are_drawn_back_to_front() {
        let cloud = CloudType::CumulusCongestus
            .spec("", 0.0, 3000.0, 1000.0, 2)
            .build();
        let mut scene = SpriteScene::new(vec![cloud]);
        let cam = Vec3::new(0.0, 0.0, 500.0);
        let inst = scene.frame(&[], Vec3::Z, cam, 0.0);
        assert!(inst.len() > 20);
        let d: Vec<f32> = inst
            .iter()
            .map(|s| {
                let c = 0.5 * (Vec4::from(s.corners[0]) + Vec4::from(s.corners[2]));
                c.truncate().distance(cam)
            })
            .collect();
        assert!(d.windows(2).all(|w| w[0] >= w[1]), "{d:?}");
        // A second frame from the same place comes from the cache.
        scene.frame(&[], Vec3::Z, cam, 0.0);
        assert_eq!(scene.stats.reshaded, 0);
        // The sun moving re-shades it.
        scene.frame(&[], Vec3::new(0.5, 0.0, 0.8), cam, 0.0);
        assert_eq!(scene.stats.reshaded, 1);
    }

    #[test]
    fn a_parcel_keeps_its_sprites_as_its_fill_changes() {
        let p = |fill: f32| CloudParcel {
            id: 0,
            center_m: Vec3::new(0.0, 2000.0, 1500.0),
            radius_m: 300.0,
            fill,
            cond_plane_z_m: 1300.0,
        };
        let mut scene = SpriteScene::default();
        let cam = Vec3::ZERO;
        let thin = scene.frame(&[p(0.8)], Vec3::Z, cam, 0.0);
        let full = scene.frame(&[p(1.0)], Vec3::Z, cam, 0.0);
        assert_eq!(thin.len(), full.len());
        for (a, b) in thin.iter().zip(&full) {
            assert_eq!(a.corners, b.corners);
        }
        // Core sprites already formed, edges still fading in at 0.8.
        let alpha = |v: &[SpriteInstance]| v.iter().map(|s| s.colors[0][3]).sum::<f32>();
        assert!(alpha(&thin) < alpha(&full));
    }

    #[test]
    fn a_parcels_sprites_survive_another_parcel_evaporating() {
        let p = |id: u64, x: f32| CloudParcel {
            id,
            center_m: Vec3::new(x, 3000.0, 1500.0),
            radius_m: 300.0,
            fill: 1.0,
            cond_plane_z_m: 1300.0,
        };
        let mut scene = SpriteScene::default();
        let cam = Vec3::ZERO;
        let both = scene.frame(&[p(1, -2000.0), p(2, 2000.0)], Vec3::Z, cam, 0.0);
        let alone = scene.frame(&[p(2, 2000.0)], Vec3::Z, cam, 0.0);
        assert!(!alone.is_empty());
        // Every sprite of parcel 2 is still drawn, corner for corner.
        assert!(alone.iter().all(|s| both.contains(s)));
        assert_eq!(both.len(), alone.len() + scene_len(&[p(1, -2000.0)]));
    }

    fn scene_len(parcels: &[CloudParcel]) -> usize {
        SpriteScene::default()
            .frame(parcels, Vec3::Z, Vec3::ZERO, 0.0)
            .len()
    }

    #[test]
    fn equivalent_hour_follows_the_sun() {
        assert!((equivalent_hour(Vec3::Z) - 12.0).abs() < 1e-3);
        // On the horizon in the east: 06:00; in the west: 18:00.
        assert!((equivalent_hour(Vec3::X) - 6.0).abs() < 1e-3);
        assert!((equivalent_hour(-Vec3::X) - 18.0).abs() < 1e-3);
        // 30° up in the east: H = acos(sin 30°) = 60° = 4 h before noon.
        let e = 30f32.to_radians();
        let d = Vec3::new(e.cos(), 0.0, e.sin());
        assert!((equivalent_hour(d) - 8.0).abs() < 1e-3);
    }
}
