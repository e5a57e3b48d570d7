//! Formation and dissipation by transparency (paper §4, Listing 1 of the
//! article 003). Forming: core sprites (centre within half the cloud radius)
//! fade in first; once they reach a threshold opacity the edge sprites fade
//! in. Dissipating reverses it: edges fade out first, then the core.
//!
//! For physics clouds the progress follows the parcel's condensed fill: it
//! moves towards `fill` (condensation forms the cloud, evaporation
//! dissipates it) at a bounded rate, so a jump in fill between physics steps
//! still fades instead of popping.

use glam::Vec3;

/// Core sprites: centre within this fraction of the cloud radius (§4).
pub const CORE_FRACTION: f32 = 0.5;
/// Core opacity at which edge sprites start to appear (the paper's
/// "threshold opacity" has no number; ours is the artist's default).
pub const THRESHOLD_OPACITY: f32 = 0.6;
/// Share of the formation progress the core takes to reach full opacity.
const CORE_SPAN: f32 = 0.6;

/// Formation alpha of a sprite at `radial` = distance from the cloud centre
/// / cloud radius, for a formation `progress` in [0, 1] (0: no cloud, 1:
/// fully formed). Dissipation runs `progress` back down.
pub fn formation_alpha(progress: f32, radial: f32) -> f32 {
    let p = progress.clamp(0.0, 1.0);
    let core = (p / CORE_SPAN).min(1.0);
    if radial <= CORE_FRACTION {
        return core;
    }
    // Edges start when the core has reached the threshold opacity.
    let start = THRESHOLD_OPACITY * CORE_SPAN;
    ((p - start) / (1.0 - start)).clamp(0.0, 1.0)
}

/// The state of Listing 1 (dissipation): `alpha_at_edges` rises from 0 to
/// 255 over `time_to_fade_cloud_edges`, then `alpha_of_cloud` falls from 255
/// over `time_to_fade_cloud_core`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Listing1 {
    /// 0–255.
    pub alpha_at_edges: f32,
    /// 0–255.
    pub alpha_of_cloud: f32,
    /// units: s
    pub time_to_fade_cloud_edges: f32,
    /// units: s
    pub time_to_fade_cloud_core: f32,
}

impl Listing1 {
    /// A cloud about to dissipate.
    pub fn new(time_to_fade_cloud_edges: f32, time_to_fade_cloud_core: f32) -> Self {
        Listing1 {
            alpha_at_edges: 0.0,
            alpha_of_cloud: 255.0,
            time_to_fade_cloud_edges,
            time_to_fade_cloud_core,
        }
    }

    /// Alpha of a vertex at `vertex` (relative to the cloud centre), as the
    /// listing prints it: radial = max(0, R − |v|); alpha = (alpha_of_cloud −
    /// radial·alpha_at_edges/R)/255, clamped to [0, 1]. As printed, vertices
    /// nearer the centre lose more alpha in the edge phase, unlike the text
    /// (edges first); we keep the listing verbatim for reference and draw
    /// with [`formation_alpha`], which follows the text.
    pub fn alpha(&self, vertex: Vec3, cloud_radius: f32) -> f32 {
        let radial = (cloud_radius - vertex.length()).max(0.0);
        ((self.alpha_of_cloud - radial * self.alpha_at_edges / cloud_radius) / 255.0)
            .clamp(0.0, 1.0)
    }

    /// Advances the listing by `time_delta` seconds.
    pub fn step(&mut self, time_delta: f32) {
        if self.alpha_at_edges < 255.0 {
            self.alpha_at_edges += 255.0 * time_delta / self.time_to_fade_cloud_edges;
        } else {
            self.alpha_of_cloud -= 255.0 * time_delta / self.time_to_fade_cloud_core;
        }
    }
}

/// Formation progress of a physics cloud, following its parcel's fill.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParcelFade {
    /// Current progress in [0, 1].
    pub progress: f32,
    /// Seconds for a full formation or dissipation at most speed. units: s
    pub time_to_form_s: f32,
}

impl ParcelFade {
    /// A cloud not yet visible.
    pub fn new(time_to_form_s: f32) -> Self {
        ParcelFade {
            progress: 0.0,
            time_to_form_s,
        }
    }

    /// Moves towards `fill` (the parcel's condensed fraction in [0, 1]) by at
    /// most `dt / time_to_form_s`: rising fill (condensation) forms the
    /// cloud core first, falling fill (evaporation) dissipates its edges first.
    pub fn update(&mut self, fill: f32, dt_s: f32) -> f32 {
        let target = if fill.is_finite() {
            fill.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let step = (dt_s / self.time_to_form_s.max(1e-3)).max(0.0);
        self.progress += (target - self.progress).clamp(-step, step);
        self.progress
    }
}
