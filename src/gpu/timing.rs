//! Frame timing: per-pass GPU timestamps (read back at once, or lagged so
//! the window never waits for the GPU) or, without timestamp support, the
//! CPU clock with a queue sync per pass. The renderer only says which
//! passes it encoded; this module owns the query set and the readback.

use std::sync::{Arc, Mutex};

use crate::error::{Error, Result};
use crate::gpu::GpuContext;

/// How long each pass of one frame took.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FrameTimings {
    /// (pass name, milliseconds), in execution order.
    pub passes: Vec<(String, f64)>,
    /// GPU time of the whole frame: from the first pass's start to the last
    /// pass's end timestamp (includes gaps between passes); with CPU timing,
    /// the sum of the passes. units: ms
    pub frame_ms: f64,
    /// true: GPU timestamps; false: CPU wall clock with a queue sync per pass.
    pub gpu_timestamps: bool,
    /// CPU time of the last `prepare` (packing + buffer writes). units: ms
    pub upload_ms: f64,
}

impl FrameTimings {
    /// Sum of the pass times. units: ms
    pub fn total_ms(&self) -> f64 {
        self.passes.iter().map(|(_, ms)| ms).sum()
    }

    /// Time of one pass, if it ran. units: ms
    pub fn pass_ms(&self, name: &str) -> Option<f64> {
        self.passes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, ms)| *ms)
    }
}

/// How `render` times its passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimingMode {
    /// GPU timestamps read back at the end of each frame (waits for the
    /// GPU; exact per frame: headless commands, bench, tests). The default.
    GpuBlocking,
    /// GPU timestamps read back when ready, without waiting: `render`
    /// returns the latest finished frame's timings (a frame or more old).
    /// For the window, so timing does not stall the frame.
    GpuLagged,
    /// CPU wall clock with a queue wait after each pass.
    Cpu,
}

/// (pass names, whole frame ms) of one measured frame.
type Measured = (Vec<(String, f64)>, f64);

/// A lagged read-back under way: the passes it times and the flag its
/// mapping sets when done (Err: mapping failed).
type InFlight = (Vec<&'static str>, Arc<Mutex<Option<bool>>>);

/// Timestamp queries: two per pass (begin, end).
pub(crate) struct Timestamps {
    pub set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    /// Lagged mode: the read buffer is being mapped for these passes;
    /// the flag turns true when the mapping is done (Err: mapping failed).
    in_flight: Option<InFlight>,
    /// Lagged mode: the latest timings read back.
    last: Measured,
}

impl Timestamps {
    /// Queries for up to `passes` passes a frame.
    pub fn new(device: &wgpu::Device, passes: u32) -> Self {
        let count = 2 * passes;
        let bytes = 8 * count as u64;
        Self {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("pass timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolve: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp resolve"),
                size: bytes,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            }),
            read: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("timestamp read"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            in_flight: None,
            last: (Vec::new(), 0.0),
        }
    }

    /// Whether the lagged mode can measure this frame (no readback pending).
    pub fn lagged_ready(&self) -> bool {
        self.in_flight.is_none()
    }

    /// Copies the timestamps of `n` passes toward the read buffer.
    pub fn resolve(&self, enc: &mut wgpu::CommandEncoder, n: u32) {
        enc.resolve_query_set(&self.set, 0..2 * n, &self.resolve, 0);
        enc.copy_buffer_to_buffer(&self.resolve, 0, &self.read, 0, 16 * n as u64);
    }

    /// Blocking readback of the frame just submitted.
    pub fn read_now(&self, ctx: &GpuContext, names: &[&'static str]) -> Measured {
        let n = names.len() as u64;
        let ticks = read_buffer(ctx, &self.read, 16 * n)
            .map(|b| bytemuck::pod_collect_to_vec::<u8, u64>(&b))
            .unwrap_or_default();
        to_ms(ctx, names, &ticks)
    }

    /// Lagged readback: collects a finished mapping (if any) and returns
    /// the latest measured frame.
    pub fn collect(&mut self, ctx: &GpuContext) -> Measured {
        let _ = ctx.device.poll(wgpu::PollType::Poll);
        if let Some((names, flag)) = &self.in_flight {
            let state = *flag.lock().unwrap_or_else(|e| e.into_inner());
            if let Some(ok) = state {
                if ok {
                    let n = names.len() as u64;
                    if let Ok(view) = self.read.get_mapped_range(0..16 * n) {
                        let ticks = bytemuck::pod_collect_to_vec::<u8, u64>(&view);
                        self.last = to_ms(ctx, names, &ticks);
                    }
                    self.read.unmap();
                }
                self.in_flight = None;
            }
        }
        self.last.clone()
    }

    /// Lagged mode: starts mapping the frame just submitted.
    pub fn start_map(&mut self, names: Vec<&'static str>) {
        let n = names.len() as u64;
        let flag = Arc::new(Mutex::new(None));
        let setter = flag.clone();
        self.read
            .map_async(wgpu::MapMode::Read, 0..16 * n, move |r| {
                *setter.lock().unwrap_or_else(|e| e.into_inner()) = Some(r.is_ok());
            });
        self.in_flight = Some((names, flag));
    }
}

fn to_ms(ctx: &GpuContext, names: &[&'static str], ticks: &[u64]) -> Measured {
    let period_ns = ctx.queue.get_timestamp_period() as f64;
    let ms = |a: u64, b: u64| b.saturating_sub(a) as f64 * period_ns / 1e6;
    let passes = names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let t = match (ticks.get(2 * i), ticks.get(2 * i + 1)) {
                (Some(a), Some(b)) => ms(*a, *b),
                _ => f64::NAN,
            };
            (name.to_string(), t)
        })
        .collect();
    let frame = match (ticks.first(), ticks.get(2 * names.len().max(1) - 1)) {
        (Some(a), Some(b)) => ms(*a, *b),
        _ => f64::NAN,
    };
    (passes, frame)
}

/// Maps `buffer` (MAP_READ), waits, and copies out its first `size` bytes.
pub(crate) fn read_buffer(ctx: &GpuContext, buffer: &wgpu::Buffer, size: u64) -> Result<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, 0..size, move |r| {
        let _ = tx.send(r);
    });
    ctx.wait_idle();
    rx.recv()
        .map_err(|e| Error::Gpu(format!("readback never completed: {e}")))?
        .map_err(|e| Error::Gpu(format!("readback failed: {e}")))?;
    let bytes = buffer
        .get_mapped_range(0..size)
        .map_err(|e| Error::Gpu(format!("readback mapping: {e}")))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
}

/// Records a frame's passes, each timed: with GPU timestamps, into one
/// command encoder (each pass given its pair of query indices, or none
/// when this frame is not measured); with the CPU clock, each pass in an
/// encoder of its own, submitted and waited for. A method encodes its
/// passes through [`Recorder::pass`] and never sees which.
pub struct Recorder<'a> {
    ctx: &'a GpuContext,
    /// The frame's encoder (GPU timing).
    enc: Option<wgpu::CommandEncoder>,
    /// The query set when this frame is measured.
    queries: Option<&'a wgpu::QuerySet>,
    /// Passes encoded, in order (GPU timing).
    pub names: Vec<&'static str>,
    /// CPU timing: each pass's wall-clock time. units: ms
    pub cpu: Option<Vec<(String, f64)>>,
}

impl<'a> Recorder<'a> {
    /// GPU timing into one encoder; `queries` when this frame is measured.
    pub fn gpu(ctx: &'a GpuContext, queries: Option<&'a wgpu::QuerySet>) -> Self {
        Self {
            ctx,
            enc: Some(ctx.device.create_command_encoder(&Default::default())),
            queries,
            names: Vec::new(),
            cpu: None,
        }
    }

    /// CPU timing: a queue wait after each pass.
    pub fn cpu(ctx: &'a GpuContext) -> Self {
        Self {
            ctx,
            enc: None,
            queries: None,
            names: Vec::new(),
            cpu: Some(Vec::new()),
        }
    }

    /// Encodes one pass named `name` (its timing name): `f` gets the
    /// encoder and, when measured, (query set, index of the pass's begin
    /// query; the end query follows).
    pub fn pass<R>(
        &mut self,
        name: &'static str,
        f: impl FnOnce(&mut wgpu::CommandEncoder, Option<(&wgpu::QuerySet, u32)>) -> R,
    ) -> R {
        match (&mut self.enc, &mut self.cpu) {
            (Some(enc), _) => {
                let i = 2 * self.names.len() as u32;
                self.names.push(name);
                f(enc, self.queries.map(|q| (q, i)))
            }
            (None, Some(times)) => {
                let start = std::time::Instant::now();
                let mut enc = self.ctx.device.create_command_encoder(&Default::default());
                let r = f(&mut enc, None);
                self.ctx.queue.submit([enc.finish()]);
                self.ctx.wait_idle();
                times.push((name.to_string(), start.elapsed().as_secs_f64() * 1e3));
                r
            }
            (None, None) => unreachable!("a recorder times on the GPU or the CPU"),
        }
    }

    /// The frame's encoder (GPU timing), to resolve the queries and submit.
    pub fn finish(self) -> (Option<wgpu::CommandEncoder>, Vec<&'static str>) {
        (self.enc, self.names)
    }
}

/// A compute pass's timestamp writes at query `i` and `i + 1`.
pub fn compute_writes(
    ts: Option<(&wgpu::QuerySet, u32)>,
) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
    ts.map(|(set, i)| wgpu::ComputePassTimestampWrites {
        query_set: set,
        beginning_of_pass_write_index: Some(i),
        end_of_pass_write_index: Some(i + 1),
    })
}

/// A render pass's timestamp writes at query `i` and `i + 1`.
pub fn render_writes(
    ts: Option<(&wgpu::QuerySet, u32)>,
) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
    ts.map(|(set, i)| wgpu::RenderPassTimestampWrites {
        query_set: set,
        beginning_of_pass_write_index: Some(i),
        end_of_pass_write_index: Some(i + 1),
    })
}
