//! `march = "auto"`: the renderer measures both march paths on the adapter
//! at hand and keeps the faster, without extra work or a wait. While
//! undecided, frames with clouds alternate fragment and compute; the pass
//! timings that come back (at once, or a frame or more late in the lagged
//! mode) say which path a frame used (a compute frame has a `composite`
//! pass). The first frame of each path is dropped (drivers compile on first
//! use), then the path with the lower median of [`SAMPLES`] frames wins.

use crate::config::method::MarchPath;
use crate::gpu::timing::FrameTimings;

/// Frames measured per path (after the dropped first one).
pub const SAMPLES: usize = 2;

/// The measurements so far; see the module docs.
#[derive(Debug, Clone, Default)]
pub struct AutoMarch {
    /// Cloud-pass times (compute: + composite). units: ms
    fragment: Vec<f64>,
    compute: Vec<f64>,
    chosen: Option<MarchPath>,
    /// Frames with clouds drawn while undecided.
    frames: u64,
}

impl AutoMarch {
    /// The path of the next frame with clouds: `configured` unless it is
    /// Auto, then the decision or, while undecided, alternately each.
    pub fn path(&self, configured: MarchPath) -> MarchPath {
        match (configured, self.chosen) {
            (MarchPath::Auto, Some(p)) => p,
            (MarchPath::Auto, None) if self.frames % 2 == 1 => MarchPath::Compute,
            (MarchPath::Auto, None) => MarchPath::Fragment,
            (p, _) => p,
        }
    }

    /// The decision, once made.
    pub fn chosen(&self) -> Option<MarchPath> {
        self.chosen
    }

    /// Counts a frame with clouds drawn while undecided.
    pub fn drew(&mut self) {
        if self.chosen.is_none() {
            self.frames += 1;
        }
    }

    /// Takes the timings of a (possibly earlier) frame.
    pub fn record(&mut self, t: &FrameTimings) {
        if self.chosen.is_some() {
            return;
        }
        let Some(clouds) = t.pass_ms("clouds") else {
            return;
        };
        match t.pass_ms("composite") {
            Some(c) => self.compute.push(clouds + c),
            None => self.fragment.push(clouds),
        }
        if self.fragment.len() > SAMPLES && self.compute.len() > SAMPLES {
            let median = |v: &[f64]| {
                let mut s = v[1..].to_vec();
                s.sort_by(f64::total_cmp);
                s[s.len() / 2]
            };
            self.chosen = Some(if median(&self.compute) < median(&self.fragment) {
                MarchPath::Compute
            } else {
                MarchPath::Fragment
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(clouds: f64, composite: Option<f64>) -> FrameTimings {
        let mut passes = vec![("clouds".to_string(), clouds)];
        if let Some(c) = composite {
            passes.push(("composite".to_string(), c));
        }
        FrameTimings {
            passes,
            ..FrameTimings::default()
        }
    }

    #[test]
    fn alternates_then_keeps_the_faster_ignoring_first_frames() {
        let mut a = AutoMarch::default();
        assert_eq!(a.path(MarchPath::Fragment), MarchPath::Fragment);
        assert_eq!(a.path(MarchPath::Auto), MarchPath::Fragment);
        a.drew();
        assert_eq!(a.path(MarchPath::Auto), MarchPath::Compute);
        // First frames are slow (compile), then compute is faster.
        a.record(&frame(900.0, None));
        a.record(&frame(5.0, Some(1.0)));
        for _ in 0..SAMPLES {
            assert_eq!(a.chosen(), None);
            a.record(&frame(10.0, None));
            a.record(&frame(5.0, Some(1.0)));
        }
        assert_eq!(a.chosen(), Some(MarchPath::Compute));
        assert_eq!(a.path(MarchPath::Auto), MarchPath::Compute);
        // An explicit path is kept whatever was measured.
        assert_eq!(a.path(MarchPath::Fragment), MarchPath::Fragment);
    }
}
