//! What a pass needs from the adapter, read from the pass's own
//! declaration (its [`crate::gpu::pass::PassSpec`]: kind, bind-group
//! layouts, colour target) and its WGSL module (workgroup sizes, uniform
//! sizes), and checked against the device before any pipeline is made, so
//! that an adapter that cannot run a pass gets an error naming the pass,
//! the limit or feature and what the adapter has, never a wgpu
//! validation error at draw time.
//!
//! The counts follow wgpu's own validation: bindings are counted per
//! shader stage from the layouts' visibility, over every group of the
//! pipeline layout.

use crate::gpu::GpuContext;

/// A limit of [`wgpu::Limits`] by name.
#[derive(Clone, Copy)]
pub struct Limit {
    pub name: &'static str,
    pub get: fn(&wgpu::Limits) -> u64,
}

macro_rules! limit {
    ($field:ident) => {
        Limit {
            name: stringify!($field),
            get: |l| l.$field as u64,
        }
    };
}

/// One thing a pass needs.
#[derive(Clone, Copy)]
pub enum Need {
    /// Compute shaders (`DownlevelFlags::COMPUTE_SHADERS`).
    Compute,
    /// A limit of at least `at_least`.
    Limit { limit: Limit, at_least: u64 },
    /// A texture format with these usages (and blending, for a blended
    /// colour target).
    Format {
        format: wgpu::TextureFormat,
        usages: wgpu::TextureUsages,
        blendable: bool,
        /// What the pass does with it.
        role: &'static str,
    },
}

impl std::fmt::Debug for Need {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Need::Compute => write!(f, "compute shaders"),
            Need::Limit { limit, at_least } => write!(f, "{} ≥ {at_least}", limit.name),
            Need::Format { format, role, .. } => write!(f, "{format:?} as {role}"),
        }
    }
}

/// What one pass needs.
#[derive(Debug, Clone)]
pub struct Requirement {
    pub pass: String,
    pub needs: Vec<Need>,
}

/// What the device offers, as the check reads it.
pub struct Capabilities {
    pub limits: wgpu::Limits,
    /// Compute shaders are available.
    pub compute: bool,
    /// The features of a texture format.
    pub formats: Box<dyn Fn(wgpu::TextureFormat) -> wgpu::TextureFormatFeatures>,
}

impl Capabilities {
    /// The device's limits, the adapter's downlevel flags and formats.
    pub fn of(ctx: &GpuContext) -> Self {
        let adapter = ctx.adapter.clone();
        Self {
            limits: ctx.device.limits(),
            compute: ctx
                .adapter
                .get_downlevel_capabilities()
                .flags
                .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS),
            formats: Box::new(move |f| adapter.get_texture_format_features(f)),
        }
    }
}

/// A need the device does not meet: what and what the device has.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Missing {
    pub pass: String,
    pub need: String,
    pub have: String,
}

impl std::fmt::Display for Missing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "its {} pass needs {}, the device has {}",
            self.pass, self.need, self.have
        )
    }
}

impl Requirement {
    /// The first need `caps` does not meet.
    pub fn check(&self, caps: &Capabilities) -> Result<(), Missing> {
        for need in &self.needs {
            let have = match *need {
                Need::Compute => (!caps.compute).then(|| "no compute shaders".to_string()),
                Need::Limit { limit, at_least } => {
                    let v = (limit.get)(&caps.limits);
                    (v < at_least).then(|| format!("{} = {v}", limit.name))
                }
                Need::Format {
                    format,
                    usages,
                    blendable,
                    ..
                } => {
                    let f = (caps.formats)(format);
                    let ok = f.allowed_usages.contains(usages)
                        && (!blendable
                            || f.flags.contains(wgpu::TextureFormatFeatureFlags::BLENDABLE));
                    (!ok).then(|| format!("{format:?} allowing only {:?}", f.allowed_usages))
                }
            };
            if let Some(have) = have {
                return Err(Missing {
                    pass: self.pass.clone(),
                    need: format!("{need:?}"),
                    have,
                });
            }
        }
        Ok(())
    }

    /// The needs of a pipeline named `pass`: compute or render (with its
    /// colour target and whether it blends), the entries of its bind
    /// groups in order (None: an unused group), and its assembled WGSL
    /// `source` (workgroup sizes, uniform sizes; a module naga cannot
    /// parse adds nothing, the tests parse every module).
    pub fn of(
        pass: &str,
        compute: bool,
        target: Option<(wgpu::TextureFormat, bool)>,
        groups: &[Option<&[wgpu::BindGroupLayoutEntry]>],
        source: &str,
    ) -> Self {
        let mut needs = Vec::new();
        let mut at_least = |limit: Limit, v: u64| {
            if v > 0 {
                needs.push(Need::Limit { limit, at_least: v });
            }
        };
        at_least(limit!(max_bind_groups), groups.len() as u64);
        let entries: Vec<&wgpu::BindGroupLayoutEntry> =
            groups.iter().flatten().flat_map(|g| g.iter()).collect();
        let per_stage = |is: fn(&wgpu::BindingType) -> bool| -> u64 {
            [
                wgpu::ShaderStages::VERTEX,
                wgpu::ShaderStages::FRAGMENT,
                wgpu::ShaderStages::COMPUTE,
            ]
            .iter()
            .map(|s| {
                entries
                    .iter()
                    .filter(|e| e.visibility.contains(*s) && is(&e.ty))
                    .count() as u64
            })
            .max()
            .unwrap_or(0)
        };
        use wgpu::{BindingType as B, BufferBindingType as Bb};
        at_least(
            limit!(max_uniform_buffers_per_shader_stage),
            per_stage(|t| {
                matches!(
                    t,
                    B::Buffer {
                        ty: Bb::Uniform,
                        ..
                    }
                )
            }),
        );
        at_least(
            limit!(max_storage_buffers_per_shader_stage),
            per_stage(|t| {
                matches!(
                    t,
                    B::Buffer {
                        ty: Bb::Storage { .. },
                        ..
                    }
                )
            }),
        );
        at_least(
            limit!(max_storage_textures_per_shader_stage),
            per_stage(|t| matches!(t, B::StorageTexture { .. })),
        );
        at_least(
            limit!(max_sampled_textures_per_shader_stage),
            per_stage(|t| matches!(t, B::Texture { .. })),
        );
        at_least(
            limit!(max_samplers_per_shader_stage),
            per_stage(|t| matches!(t, B::Sampler(_))),
        );
        let module = naga::front::wgsl::parse_str(source).ok();
        if let Some(m) = &module {
            let uniform = m
                .global_variables
                .iter()
                .filter(|(_, g)| g.space == naga::AddressSpace::Uniform)
                .map(|(_, g)| m.types[g.ty].inner.size(m.to_ctx()) as u64)
                .max()
                .unwrap_or(0);
            at_least(limit!(max_uniform_buffer_binding_size), uniform);
        }
        if compute {
            let sizes: Vec<[u32; 3]> = module
                .iter()
                .flat_map(|m| m.entry_points.iter())
                .filter(|e| e.stage == naga::ShaderStage::Compute)
                .map(|e| e.workgroup_size)
                .collect();
            let axis = |i: usize| sizes.iter().map(|s| s[i] as u64).max().unwrap_or(1);
            at_least(limit!(max_compute_workgroup_size_x), axis(0));
            at_least(limit!(max_compute_workgroup_size_y), axis(1));
            at_least(limit!(max_compute_workgroup_size_z), axis(2));
            at_least(
                limit!(max_compute_invocations_per_workgroup),
                sizes
                    .iter()
                    .map(|s| s.iter().map(|&v| v as u64).product::<u64>())
                    .max()
                    .unwrap_or(1),
            );
        }
        if compute {
            needs.insert(0, Need::Compute);
        }
        for e in &entries {
            if let B::StorageTexture { format, .. } = e.ty {
                needs.push(Need::Format {
                    format,
                    usages: wgpu::TextureUsages::STORAGE_BINDING,
                    blendable: false,
                    role: "a storage texture",
                });
            }
        }
        if let Some((format, blend)) = target {
            needs.push(Need::Format {
                format,
                usages: wgpu::TextureUsages::RENDER_ATTACHMENT,
                blendable: blend,
                role: if blend {
                    "a blended colour target"
                } else {
                    "a colour target"
                },
            });
        }
        Self {
            pass: pass.to_string(),
            needs,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn full(limits: wgpu::Limits) -> Capabilities {
        Capabilities {
            limits,
            compute: true,
            formats: Box::new(|_| wgpu::TextureFormatFeatures {
                allowed_usages: wgpu::TextureUsages::all(),
                flags: wgpu::TextureFormatFeatureFlags::all(),
            }),
        }
    }

    const STORAGE_3D: &[wgpu::BindGroupLayoutEntry] = &[
        crate::gpu::layouts::storage_texture_entry_of(
            0,
            wgpu::TextureFormat::Rgba16Float,
            wgpu::TextureViewDimension::D3,
        ),
        crate::gpu::layouts::compute_storage_entry(1),
    ];

    const WGSL: &str = "
        struct Big { a: array<vec4<f32>, 2048> }
        @group(0) @binding(0) var<uniform> big: Big;
        @compute @workgroup_size(4, 4, 4) fn cs() { _ = big.a[0]; }
    ";

    fn job() -> Requirement {
        Requirement::of("job", true, None, &[Some(STORAGE_3D)], WGSL)
    }

    #[test]
    fn a_pass_reads_its_workgroup_and_uniform_sizes_from_its_module() {
        let r = job();
        let text = format!("{:?}", r.needs);
        for want in [
            "compute shaders",
            "max_compute_workgroup_size_z ≥ 4",
            "max_compute_invocations_per_workgroup ≥ 64",
            "max_uniform_buffer_binding_size ≥ 32768",
            "max_storage_textures_per_shader_stage ≥ 1",
            "max_storage_buffers_per_shader_stage ≥ 1",
            "Rgba16Float as a storage texture",
        ] {
            assert!(text.contains(want), "{want} not in {text}");
        }
    }

    #[test]
    fn the_default_limits_run_the_pass() {
        assert_eq!(job().check(&full(wgpu::Limits::default())), Ok(()));
    }

    #[test]
    fn limits_below_ours_are_named() {
        let low = wgpu::Limits {
            max_compute_workgroup_size_z: 1,
            ..wgpu::Limits::default()
        };
        let e = job().check(&full(low)).unwrap_err();
        assert_eq!(e.need, "max_compute_workgroup_size_z ≥ 4");
        assert_eq!(e.have, "max_compute_workgroup_size_z = 1");
        let low = wgpu::Limits {
            max_uniform_buffer_binding_size: 16 << 10,
            ..wgpu::Limits::default()
        };
        let e = job().check(&full(low)).unwrap_err();
        assert!(
            e.to_string()
                .contains("max_uniform_buffer_binding_size ≥ 32768"),
            "{e}"
        );
        // WebGL 2's limits have no storage textures at all.
        let e = job()
            .check(&full(wgpu::Limits::downlevel_webgl2_defaults()))
            .unwrap_err();
        assert!(e.need.starts_with("max_"), "{e}");
    }

    #[test]
    fn no_compute_or_a_missing_format_is_named() {
        let mut caps = full(wgpu::Limits::default());
        caps.compute = false;
        assert_eq!(job().check(&caps).unwrap_err().need, "compute shaders");
        let mut caps = full(wgpu::Limits::default());
        caps.formats = Box::new(|_| wgpu::TextureFormatFeatures {
            allowed_usages: wgpu::TextureUsages::TEXTURE_BINDING,
            flags: wgpu::TextureFormatFeatureFlags::empty(),
        });
        let e = job().check(&caps).unwrap_err();
        assert_eq!(e.need, "Rgba16Float as a storage texture");
    }
}
