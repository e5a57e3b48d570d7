//! Building pipelines ahead on a background thread, so that toggling an
//! option in the window does not stop a frame for a shader compile ("no
//! stalls"). The renderer asks for the pipelines of every setting
//! one panel click away from the current one (see
//! `Renderer::request_neighbours`); one worker thread compiles them in
//! turn on its own clone of the device and hands them back through a
//! channel, which the renderer drains at each frame. A pipeline a frame
//! needs while the worker is still on it is waited for rather than built
//! twice. The headless commands and the tests leave this off unless they
//! ask: it would compile pipelines nobody uses.

use std::collections::HashSet;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, mpsc};
use std::thread::JoinHandle;

use crate::gpu::pipelines::{Layouts, Pipeline, PipelineKey, ShaderModules};

/// A finished build: the key and its pipeline (None: it failed; the
/// renderer then builds it itself to report the error).
type Done = (PipelineKey, Option<Pipeline>);

/// The worker thread and what has been asked of it.
pub struct Prebuilder {
    jobs: Option<mpsc::Sender<PipelineKey>>,
    done: mpsc::Receiver<Done>,
    /// Asked for and not yet handed back.
    pending: HashSet<PipelineKey>,
    /// Set when dropped: the worker leaves the rest of its queue.
    stop: Arc<AtomicBool>,
    worker: Option<JoinHandle<()>>,
}

impl Prebuilder {
    pub fn new(device: wgpu::Device, layouts: Layouts) -> Self {
        let (jobs, rx) = mpsc::channel::<PipelineKey>();
        let (tx, done) = mpsc::channel::<Done>();
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = stop.clone();
        let worker = std::thread::Builder::new()
            .name("pipeline prebuild".into())
            .spawn(move || {
                let mut modules = ShaderModules::default();
                for key in rx {
                    if stopped.load(Ordering::Relaxed) {
                        break;
                    }
                    // Error scopes belong to the thread that pushes them.
                    let built = crate::gpu::catching(&device, "prebuild", || {
                        modules.build(&device, &layouts, &key)
                    })
                    .ok();
                    if built.is_none() {
                        modules.forget(&key);
                    }
                    if tx.send((key, built)).is_err() {
                        break;
                    }
                }
            })
            .ok();
        Self {
            jobs: worker.is_some().then_some(jobs),
            done,
            pending: HashSet::new(),
            stop,
            worker,
        }
    }

    /// Queues `key` unless it is already queued.
    pub fn request(&mut self, key: &PipelineKey) {
        if let Some(jobs) = &self.jobs
            && !self.pending.contains(key)
            && jobs.send(key.clone()).is_ok()
        {
            self.pending.insert(key.clone());
        }
    }

    pub fn is_pending(&self, key: &PipelineKey) -> bool {
        self.pending.contains(key)
    }

    /// What has finished, without waiting.
    pub fn finished(&mut self) -> Vec<Done> {
        let mut out = Vec::new();
        while let Ok(d) = self.done.try_recv() {
            self.pending.remove(&d.0);
            out.push(d);
        }
        out
    }

    /// Waits until `key` is done; returns everything finished meanwhile.
    pub fn wait_for(&mut self, key: &PipelineKey) -> Vec<Done> {
        self.wait_while(|pending| pending.contains(key))
    }

    /// Waits until everything asked for is done.
    pub fn wait_all(&mut self) -> Vec<Done> {
        self.wait_while(|pending| !pending.is_empty())
    }

    /// Receives finished builds while `waiting(pending)` holds (or the
    /// worker is gone).
    fn wait_while(&mut self, waiting: impl Fn(&HashSet<PipelineKey>) -> bool) -> Vec<Done> {
        let mut out = Vec::new();
        while waiting(&self.pending) {
            let Ok(d) = self.done.recv() else {
                self.pending.clear();
                break;
            };
            self.pending.remove(&d.0);
            out.push(d);
        }
        out
    }
}

impl Drop for Prebuilder {
    fn drop(&mut self) {
        // The worker ends after its current build (a window closing does
        // not wait for the queue).
        self.stop.store(true, Ordering::Relaxed);
        self.jobs = None;
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
    }
}
