//! The GPU context: instance, adapter, device and queue, opened headless or
//! for a window surface. Requests timestamp queries when the adapter has
//! them (per-pass GPU timings) and says which adapter it got, for reports.

use crate::error::{Error, Result};

/// Rank of an adapter, lower first: Vulkan, Metal and DirectX 12 before
/// OpenGL/GLES (which runs fewer of our passes; it is taken when nothing
/// else exists, or when `WGPU_BACKEND` asks for it, since the instance
/// then offers nothing else), then a discrete GPU before an integrated,
/// virtual or software one.
pub fn preference(info: &wgpu::AdapterInfo) -> (u8, u8) {
    let backend = match info.backend {
        wgpu::Backend::Vulkan | wgpu::Backend::Metal | wgpu::Backend::Dx12 => 0,
        wgpu::Backend::Gl => 1,
        _ => 2,
    };
    let device = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    };
    (backend, device)
}

/// An open GPU device and what it is.
pub struct GpuContext {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// Timestamp queries are enabled (per-pass GPU timings).
    pub timestamps: bool,
    /// GPU errors raised outside every error scope since the last
    /// [`GpuContext::take_errors`] (the window shows them in its panel).
    errors: std::sync::Arc<std::sync::Mutex<Vec<String>>>,
}

fn instance() -> wgpu::Instance {
    // Honour WGPU_BACKEND etc. so a user can pick a backend.
    wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env())
}

impl GpuContext {
    /// Opens a device without a window. `prefer`: a case-insensitive part of
    /// the adapter name to pick (e.g. "llvmpipe"); None = the default choice,
    /// falling back to any adapter (a CPU one included).
    pub fn new_headless(prefer: Option<&str>) -> Result<Self> {
        let instance = instance();
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        let names: Vec<String> = adapters
            .iter()
            .map(|a| {
                let i = a.get_info();
                format!("{} ({:?})", i.name, i.backend)
            })
            .collect();
        let adapter = match prefer {
            Some(want) if !adapters.is_empty() => {
                let want_l = want.to_lowercase();
                // Adapters exist, just none by that name: a usage error,
                // not a missing driver.
                adapters
                    .into_iter()
                    .find(|a| a.get_info().name.to_lowercase().contains(&want_l))
                    .ok_or_else(|| {
                        Error::invalid(
                            "adapter name",
                            format!("{want:?}"),
                            format!(
                                "no adapter's name contains it (any case); the adapters here are: {}",
                                names.join(", ")
                            ),
                        )
                    })?
            }
            Some(want) => {
                return Err(Error::NoAdapter(format!(
                    "none found, so none named like {want:?}"
                )));
            }
            None => adapters
                .into_iter()
                .min_by_key(|a| preference(&a.get_info()))
                .ok_or_else(|| Error::NoAdapter("adapters found: none".into()))?,
        };
        Self::from_adapter(instance, adapter)
    }

    /// Opens a device that can present to `surface` (made by the window from
    /// `instance`).
    pub fn new_for_surface(instance: wgpu::Instance, surface: &wgpu::Surface<'_>) -> Result<Self> {
        let opts = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: Some(surface),
            ..Default::default()
        };
        // The same ranking as headless among the adapters that can present
        // here (WGPU_BACKEND has already narrowed the instance), then
        // wgpu's own choice.
        let adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::all()));
        let ranked = adapters
            .into_iter()
            .filter(|a| a.is_surface_supported(surface))
            .min_by_key(|a| preference(&a.get_info()));
        let adapter = match ranked {
            Some(a) => a,
            None => pollster::block_on(instance.request_adapter(&opts))
                .map_err(|e| Error::NoAdapter(format!("none can present to this window: {e}")))?,
        };
        Self::from_adapter(instance, adapter)
    }

    /// The GPU errors raised outside every error scope since the last call
    /// (at most 8), oldest first.
    pub fn take_errors(&self) -> Vec<String> {
        std::mem::take(&mut *self.errors.lock().unwrap_or_else(|p| p.into_inner()))
    }

    /// Wraps the device of another wgpu program that embeds the cloud
    /// renderer: cumulus then creates its resources on that device and
    /// records into that queue. GPU timestamps are used when the device was
    /// opened with [`wgpu::Features::TIMESTAMP_QUERY`].
    pub fn from_host(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> Self {
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        Self {
            instance,
            adapter,
            device,
            queue,
            timestamps,
            errors: Default::default(),
        }
    }

    /// A fresh instance like the one `new_headless` uses, connected to the
    /// window system of `display` (the window's; OpenGL needs it to
    /// present, the other backends ignore it).
    pub fn new_instance(display: Box<dyn wgpu::wgt::WgpuHasDisplayHandle>) -> wgpu::Instance {
        wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
            display,
        ))
    }

    fn from_adapter(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Self> {
        let available = adapter.features();
        let timestamps = available.contains(wgpu::Features::TIMESTAMP_QUERY);
        let required_features = if timestamps {
            wgpu::Features::TIMESTAMP_QUERY
        } else {
            wgpu::Features::empty()
        };
        // Ask for everything the adapter has: each pass's needs are checked
        // against these before it is built (crate::gpu::requires), so an
        // adapter below wgpu's defaults still opens and gets an error that
        // names the pass and the limit.
        let required_limits = adapter.limits();
        let desc = wgpu::DeviceDescriptor {
            label: Some("cumulus"),
            required_features,
            required_limits,
            ..Default::default()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&desc)).map_err(|e| {
            Error::NoAdapter(format!(
                "{} could not open a device: {e}",
                adapter.get_info().name
            ))
        })?;
        // An error outside every error scope (a resource or pass the
        // renderer did not wrap) is printed, never wgpu's panic: the
        // operations that can fail on an adapter (pipeline creation) run
        // under scopes and become errors ([`catching`]).
        let errors: std::sync::Arc<std::sync::Mutex<Vec<String>>> = Default::default();
        let sink = errors.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
            eprintln!("warning: GPU error: {e}");
            // Kept for the window's panel; a flood of the same error keeps
            // the first few.
            let mut v = sink.lock().unwrap_or_else(|p| p.into_inner());
            if v.len() < 8 {
                v.push(e.to_string());
            }
        }));
        Ok(Self {
            instance,
            adapter,
            device,
            queue,
            timestamps,
            errors,
        })
    }

    /// Adapter name, e.g. "llvmpipe (LLVM 19.1.7, 256 bits)".
    pub fn adapter_name(&self) -> String {
        self.adapter.get_info().name
    }

    /// Driver and its version, e.g. "llvmpipe Mesa 25.0".
    pub fn driver(&self) -> String {
        let i = self.adapter.get_info();
        format!("{} {}", i.driver, i.driver_info).trim().to_string()
    }

    /// Backend, e.g. "Vulkan".
    pub fn backend(&self) -> String {
        format!("{:?}", self.adapter.get_info().backend)
    }

    /// Why this adapter: the backend preference ([`preference`]) or the
    /// user's `WGPU_BACKEND`.
    pub fn choice(&self) -> String {
        let info = self.adapter.get_info();
        match std::env::var("WGPU_BACKEND") {
            Ok(v) if !v.is_empty() => format!("WGPU_BACKEND={v} chose the backend"),
            _ if info.backend == wgpu::Backend::Gl => {
                "OpenGL: no Vulkan, Metal or DirectX 12 adapter here".into()
            }
            _ => format!(
                "{:?} preferred over OpenGL, a discrete GPU over an integrated or software one",
                info.backend
            ),
        }
    }

    /// Whether this is a software (CPU) adapter.
    pub fn is_cpu(&self) -> bool {
        self.adapter.get_info().device_type == wgpu::DeviceType::Cpu
    }

    /// One line for reports: name, driver, backend.
    pub fn describe(&self) -> String {
        format!(
            "{} [{}; {}; {}]",
            self.adapter_name(),
            self.driver(),
            self.backend(),
            if self.timestamps {
                "GPU timestamps"
            } else {
                "no timestamps"
            }
        )
    }

    /// Blocks until the queue is idle.
    pub fn wait_idle(&self) {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }
}

/// A colour attachment of `view` that loads with `load` and stores the
/// result: the only kind of colour attachment the renderer and the window
/// draw into.
pub fn stored_color(
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
) -> wgpu::RenderPassColorAttachment<'_> {
    wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load,
            store: wgpu::StoreOp::Store,
        },
    }
}

/// Begins a render pass into `view` (loaded or cleared by `load`), with
/// the terrain depth when `depth` is given, timed by `ts` (begin, end).
pub fn begin_pass<'e>(
    enc: &'e mut wgpu::CommandEncoder,
    label: &'static str,
    view: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
    depth: Option<&wgpu::TextureView>,
    ts: Option<wgpu::RenderPassTimestampWrites<'_>>,
) -> wgpu::RenderPass<'e> {
    enc.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(crate::gpu::stored_color(view, load))],
        depth_stencil_attachment: depth.map(|view| wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: ts,
        occlusion_query_set: None,
        multiview_mask: None,
    })
    .forget_lifetime()
}

/// Runs `f` with every wgpu error it causes on this thread caught
/// (validation, internal (a shader the backend cannot translate, as
/// OpenGL's GLSL for some WGSL), out of memory), and returns the first as
/// an [`crate::error::Error::Gpu`] naming `what`, never wgpu's panic.
pub fn catching<T>(
    device: &wgpu::Device,
    what: &str,
    f: impl FnOnce() -> T,
) -> crate::error::Result<T> {
    let scopes = [
        wgpu::ErrorFilter::OutOfMemory,
        wgpu::ErrorFilter::Internal,
        wgpu::ErrorFilter::Validation,
    ]
    .map(|filter| device.push_error_scope(filter));
    let value = f();
    let mut first = None;
    // Popped innermost first.
    for scope in scopes.into_iter().rev() {
        if let Some(e) = pollster::block_on(scope.pop()) {
            first.get_or_insert(e);
        }
    }
    match first {
        None => Ok(value),
        Some(e) => Err(crate::error::Error::Gpu(format!("{what}: {e}"))),
    }
}
