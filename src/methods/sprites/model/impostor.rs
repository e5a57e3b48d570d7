//! The ring of impostors (paper §6.2) and the vertex-shading cache (§6.1),
//! as pure bookkeeping: which clouds go into impostors, when the ring must
//! be re-rendered, which sector to render this frame, and the crossfade
//! weights of the old and new sets. The renderer does the drawing.
//!
//! Numbers from the paper: 8 impostors of 45° and 256² texels; clouds
//! compared in 16 km² blocks; only blocks beyond the user's ring radius go
//! into impostors, and not clouds more than 2000 ft (609.6 m) above or
//! below the camera; re-render after a move of 15 % of the ring radius
//! horizontally or 2 % vertically, or a sun move past a threshold; one
//! impostor per frame (8 frames); crossfade between the two sets.

use std::f32::consts::TAU;

use glam::{Vec2, Vec3};

/// Impostors in the ring.
pub const SECTORS: usize = 8;
/// Field of view of one impostor. units: radians (45°)
pub const SECTOR_RAD: f32 = TAU / SECTORS as f32;
/// Impostor texture size. units: texels
pub const IMPOSTOR_SIZE: u32 = 256;
/// Side of a cloud block (16 km²). units: m
pub const BLOCK_SIDE_M: f32 = 4000.0;
/// Clouds farther above or below the camera stay out of impostors (2000 ft). units: m
pub const MAX_VERTICAL_M: f32 = 609.6;
/// Horizontal camera move that triggers a re-render, × ring radius.
pub const HORIZONTAL_FRACTION: f32 = 0.15;
/// Vertical camera move that triggers a re-render, × ring radius.
pub const VERTICAL_FRACTION: f32 = 0.02;

/// The 16 km² block holding `p` (blocks aligned on the world origin).
pub fn block_of(p: Vec3) -> (i32, i32) {
    (
        (p.x / BLOCK_SIDE_M).floor() as i32,
        (p.y / BLOCK_SIDE_M).floor() as i32,
    )
}

/// Ground centre of a block. units: m
pub fn block_center(b: (i32, i32)) -> Vec2 {
    (Vec2::new(b.0 as f32, b.1 as f32) + 0.5) * BLOCK_SIDE_M
}

/// The sector (0–7, counter-clockwise from +x) of the ring that `p` falls in.
pub fn sector_of(camera_m: Vec3, p: Vec3) -> usize {
    let d = (p - camera_m).truncate();
    let a = d.y.atan2(d.x).rem_euclid(TAU);
    ((a / SECTOR_RAD) as usize).min(SECTORS - 1)
}

/// Whether a cloud at `cloud_m` is drawn into the impostors: its block's
/// centre lies beyond the ring radius and the cloud is within 609.6 m of
/// the camera's height.
pub fn in_impostors(camera_m: Vec3, ring_radius_m: f32, cloud_m: Vec3) -> bool {
    let far = block_center(block_of(cloud_m)).distance(camera_m.truncate()) > ring_radius_m;
    far && (cloud_m.z - camera_m.z).abs() <= MAX_VERTICAL_M
}

/// As [`in_impostors`] for a cloud whose sprites span heights
/// `z_span_m` (bottom, top): the 2000 ft count from the cloud's nearest
/// height, so a deck whose base is 450 m above the camera is impostored
/// though its centre is 1200 m up, and a cloud whose base is more than
/// 609.6 m above the camera (or top as far below) is not.
pub fn span_in_impostors(
    camera_m: Vec3,
    ring_radius_m: f32,
    cloud_m: Vec3,
    z_span_m: (f32, f32),
) -> bool {
    let far = block_center(block_of(cloud_m)).distance(camera_m.truncate()) > ring_radius_m;
    let gap = (z_span_m.0 - camera_m.z)
        .max(camera_m.z - z_span_m.1)
        .max(0.0);
    far && gap <= MAX_VERTICAL_M
}

/// The faces of a ring centred at `ring_cam` that block `b` is drawn
/// into (paper §6.2: clouds go into impostors by 16 km² blocks). The
/// block is its 4 km square grown by `reach_m` on every side (how far its
/// clouds' sprites stick out of it); a face takes the whole block when
/// the square's angular span from the ring's centre overlaps the face's
/// 45°. A block straddling a face boundary goes whole into both faces:
/// each face's projection clips it at the shared edge, where the two
/// faces' quads meet, so it is neither cut short nor drawn twice on
/// screen. A camera inside the grown square sees the block all round.
pub fn block_faces(ring_cam: Vec3, b: (i32, i32), reach_m: f32) -> [bool; SECTORS] {
    let c = block_center(b);
    let half = 0.5 * BLOCK_SIDE_M + reach_m.max(0.0);
    let d = c - ring_cam.truncate();
    if d.x.abs() <= half && d.y.abs() <= half {
        return [true; SECTORS];
    }
    // Angles of the corners relative to the centre's direction: the
    // square does not hold the camera, so they span less than π.
    let mid = d.y.atan2(d.x);
    let wrap = |a: f32| (a + std::f32::consts::PI).rem_euclid(TAU) - std::f32::consts::PI;
    let (lo, hi) = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .into_iter()
        .map(|(sx, sy)| {
            let q = d + Vec2::new(sx, sy) * half;
            wrap(q.y.atan2(q.x) - mid)
        })
        .fold((f32::MAX, f32::MIN), |(lo, hi), a| (lo.min(a), hi.max(a)));
    std::array::from_fn(|k| {
        let off = wrap((k as f32 + 0.5) * SECTOR_RAD - mid);
        off + 0.5 * SECTOR_RAD > lo && off - 0.5 * SECTOR_RAD < hi
    })
}

/// Why the ring must be re-rendered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Trigger {
    /// No set built yet.
    First,
    Horizontal,
    Vertical,
    Sun,
    /// The clouds it holds changed (physics clouds condensed into or
    /// evaporated out of its reach), see [`ImpostorRing::invalidate`].
    Clouds,
}

/// Ring settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RingConfig {
    /// User radius of the ring. units: m
    pub radius_m: f32,
    /// Sun move that triggers a re-render (the paper gives no number). units: radians
    pub sun_threshold_rad: f32,
    /// Crossfade from the old set to the new. units: s
    pub crossfade_s: f32,
}

impl Default for RingConfig {
    fn default() -> Self {
        RingConfig {
            radius_m: 20_000.0,
            sun_threshold_rad: 2.0_f32.to_radians(),
            crossfade_s: 1.0,
        }
    }
}

/// What the renderer does with the ring this frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RingFrame {
    /// Sector to render into the new set this frame, with the camera it is rendered from.
    pub render: Option<(usize, Vec3)>,
    /// Weight of the old set (0 when none).
    pub old_weight: f32,
    /// Weight of the newest complete set.
    pub new_weight: f32,
}

/// The ring's state across frames.
#[derive(Debug, Clone, PartialEq)]
pub struct ImpostorRing {
    pub config: RingConfig,
    /// Camera and sun of the newest complete set.
    built: Option<(Vec3, Vec3)>,
    /// A set being rendered: its camera, sun and next sector.
    pending: Option<(Vec3, Vec3, usize)>,
    /// Seconds into the crossfade to the newest set; None when settled.
    fade_s: Option<f32>,
    /// Whether an older set exists to fade from.
    has_old: bool,
    /// The held clouds changed since the newest set ([`Self::invalidate`]).
    clouds_changed: bool,
}

impl ImpostorRing {
    pub fn new(config: RingConfig) -> Self {
        ImpostorRing {
            config,
            built: None,
            pending: None,
            fade_s: None,
            has_old: false,
            clouds_changed: false,
        }
    }

    /// Whether the camera or sun moved past a threshold since the newest set
    /// (or the set being rendered).
    pub fn trigger(&self, camera_m: Vec3, sun_dir: Vec3) -> Option<Trigger> {
        let Some((cam, sun)) = self.pending.map(|(c, s, _)| (c, s)).or(self.built) else {
            return Some(Trigger::First);
        };
        let r = self.config.radius_m;
        let d = camera_m - cam;
        if d.truncate().length() >= HORIZONTAL_FRACTION * r {
            Some(Trigger::Horizontal)
        } else if d.z.abs() >= VERTICAL_FRACTION * r {
            Some(Trigger::Vertical)
        } else if sun.angle_between(sun_dir) >= self.config.sun_threshold_rad {
            Some(Trigger::Sun)
        } else if self.clouds_changed {
            Some(Trigger::Clouds)
        } else {
            None
        }
    }

    /// The clouds the ring holds changed (a physics cloud beyond the
    /// radius condensed or evaporated): the next frame starts a new set
    /// unless one is being rendered.
    pub fn invalidate(&mut self) {
        self.clouds_changed = true;
    }

    /// Whether a set is being rendered (its faces spread over 8 frames).
    pub fn is_building(&self) -> bool {
        self.pending.is_some()
    }

    /// Advances one frame of `dt_s` seconds.
    pub fn frame(&mut self, camera_m: Vec3, sun_dir: Vec3, dt_s: f32) -> RingFrame {
        if self.pending.is_none() && self.trigger(camera_m, sun_dir).is_some() {
            self.pending = Some((camera_m, sun_dir, 0));
            self.clouds_changed = false;
        }
        let mut render = None;
        if let Some((cam, sun, k)) = self.pending {
            render = Some((k, cam));
            if k + 1 == SECTORS {
                self.pending = None;
                self.has_old = self.built.is_some();
                self.built = Some((cam, sun));
                self.fade_s = Some(0.0);
            } else {
                self.pending = Some((cam, sun, k + 1));
            }
        } else if let Some(t) = self.fade_s.as_mut() {
            *t += dt_s;
        }
        let w = match self.fade_s {
            Some(t) if self.has_old => (t / self.config.crossfade_s.max(1e-6)).min(1.0),
            _ => 1.0,
        };
        if w >= 1.0 {
            self.fade_s = None;
        }
        let new_weight = if self.built.is_some() { w } else { 0.0 };
        let old_weight = if self.has_old { 1.0 - w } else { 0.0 };
        RingFrame {
            render,
            old_weight,
            new_weight,
        }
    }
}

/// Vertex-shading cache thresholds (§6.1): recompute a cloud's sprite
/// vertices when the time or the camera move since the last computation
/// passes a threshold that grows with the cloud's distance (nearby sprites
/// turn more for the same move), and twice as often while it forms or
/// dissipates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadeCacheConfig {
    /// Largest sprite turn a camera move may cause before recomputing. units: radians
    pub max_turn_rad: f32,
    /// Time threshold per kilometre of distance. units: s/km
    pub time_s_per_km: f32,
    /// Time threshold bounds. units: s
    pub time_min_s: f32,
    pub time_max_s: f32,
}

impl Default for ShadeCacheConfig {
    fn default() -> Self {
        // Half a degree of turn stays below a texel's shift on a 256 px sprite.
        ShadeCacheConfig {
            max_turn_rad: 0.5_f32.to_radians(),
            time_s_per_km: 0.1,
            time_min_s: 0.05,
            time_max_s: 5.0,
        }
    }
}

/// When a cloud's vertices were last shaded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadeStamp {
    /// units: s
    pub time_s: f32,
    pub camera_m: Vec3,
}

impl ShadeCacheConfig {
    /// (distance threshold in m, time threshold in s) for a cloud `distance_m` away.
    pub fn thresholds(&self, distance_m: f32, forming: bool) -> (f32, f32) {
        let k = if forming { 0.5 } else { 1.0 };
        let dist = self.max_turn_rad * distance_m;
        let time =
            (self.time_s_per_km * distance_m / 1000.0).clamp(self.time_min_s, self.time_max_s);
        (k * dist, k * time)
    }

    /// Whether a cloud at `cloud_m`, shaded at `stamp`, needs its vertices recomputed.
    pub fn stale(
        &self,
        stamp: ShadeStamp,
        now_s: f32,
        camera_m: Vec3,
        cloud_m: Vec3,
        forming: bool,
    ) -> bool {
        self.stale_within(stamp, now_s, camera_m, cloud_m, 0.0, forming)
    }

    /// As [`Self::stale`] for a cloud of radius `radius_m`: the distance
    /// that sets the thresholds is to its nearest sprite (0 inside it), as
    /// a camera flying through turns the sprites next to it fastest.
    pub fn stale_within(
        &self,
        stamp: ShadeStamp,
        now_s: f32,
        camera_m: Vec3,
        cloud_m: Vec3,
        radius_m: f32,
        forming: bool,
    ) -> bool {
        let near = (cloud_m.distance(camera_m) - radius_m).max(0.0);
        let (d, t) = self.thresholds(near, forming);
        camera_m.distance(stamp.camera_m) > d || now_s - stamp.time_s > t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_go_whole_into_the_faces_they_reach() {
        let cam = Vec3::new(0.0, 0.0, 1000.0);
        let faces = |b, reach| -> Vec<usize> {
            let f = block_faces(cam, b, reach);
            (0..SECTORS).filter(|&k| f[k]).collect()
        };
        // Block (-2, 6) spans x −8..−4 km, 24..28 km north: 98°–108°, face 2.
        assert_eq!(faces((-2, 6), 0.0), vec![2]);
        // Block (1, 6) spans x 4..8 km: 72°–82°, face 1 alone; grown by
        // 4.5 km (clouds sticking out of it) it straddles the 90° border
        // and goes whole into both faces.
        assert_eq!(faces((1, 6), 0.0), vec![1]);
        assert_eq!(faces((1, 6), 1000.0), vec![1]);
        assert_eq!(faces((1, 6), 4500.0), vec![1, 2]);
        // Due east across the 0°/360° seam: faces 7 and 0.
        assert_eq!(faces((6, -1), 500.0), vec![0, 7]);
        // The camera inside the grown square: every face.
        assert_eq!(faces((0, 0), 0.0).len(), SECTORS);
        // A block on the 45° diagonal: both faces beside it, no others.
        assert_eq!(faces((5, 5), 0.0), vec![0, 1]);
    }

    #[test]
    fn the_2000_ft_count_from_the_clouds_nearest_height() {
        let cam = Vec3::new(0.0, 0.0, 250.0);
        let far = Vec3::new(0.0, 30_000.0, 1450.0);
        // A deck from 700 to 2200 m: its base is 450 m above the camera.
        assert!(span_in_impostors(cam, 20_000.0, far, (700.0, 2200.0)));
        assert!(!in_impostors(cam, 20_000.0, far));
        // Its base 700 m above: out, as is a camera 700 m over its top.
        assert!(!span_in_impostors(cam, 20_000.0, far, (950.0, 2200.0)));
        let above = Vec3::new(0.0, 0.0, 2900.0);
        assert!(!span_in_impostors(above, 20_000.0, far, (700.0, 2200.0)));
        // Blocks inside the ring never.
        let near = Vec3::new(0.0, 5_000.0, 400.0);
        assert!(!span_in_impostors(cam, 20_000.0, near, (300.0, 500.0)));
    }
}
