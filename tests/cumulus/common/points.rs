//! A WGSL routine evaluated on the GPU at points, for the tests that
//! compare a shader routine with its CPU twin: a compute entry `main`,
//! appended to the module, writes `out[i] = EXPR` with `p` the i-th point
//! (group 1: the points and the results); the caller binds the module's
//! other groups.

use wgpu::util::DeviceExt;

use cumulus::render::GpuContext;

/// `expr` (WGSL, of `p: vec3<f32>`) at each point of `pts` (xyz; w
/// unused), in the module `source` with the groups `bind` makes for its
/// pipeline (group index, bind group).
pub fn eval_at_points(
    ctx: &GpuContext,
    source: &str,
    expr: &str,
    pts: &[[f32; 4]],
    bind: impl FnOnce(&wgpu::ComputePipeline) -> Vec<(u32, wgpu::BindGroup)>,
) -> Vec<f32> {
    let device = &ctx.device;
    let src = format!(
        "{source}
@group(1) @binding(0) var<storage, read> pts: array<vec4<f32>>;
@group(1) @binding(1) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    if id.x < arrayLength(&pts) {{
        let p = pts[id.x].xyz;
        out[id.x] = {expr};
    }}
}}
"
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("points test"),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("points test"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let pts_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("points"),
        contents: bytemuck::cast_slice(pts),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = 4 * pts.len() as u64;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("points out"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let read = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("points read"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let io = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("points io"),
        layout: &pipeline.get_bind_group_layout(1),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: pts_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: out.as_entire_binding(),
            },
        ],
    });
    let groups = bind(&pipeline);
    let mut enc = device.create_command_encoder(&Default::default());
    {
        let mut cp = enc.begin_compute_pass(&Default::default());
        cp.set_pipeline(&pipeline);
        cp.set_bind_group(1, &io, &[]);
        for (i, g) in &groups {
            cp.set_bind_group(*i, g, &[]);
        }
        cp.dispatch_workgroups((pts.len() as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &read, 0, size);
    ctx.queue.submit([enc.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    read.slice(..).map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.wait_idle();
    rx.recv().unwrap().unwrap();
    let bytes = read.get_mapped_range(0..size).unwrap().to_vec();
    bytemuck::cast_slice(&bytes).to_vec()
}

/// A bind group of `pipeline`'s group `group` with `entries` (binding,
/// resource).
pub fn group_of(
    device: &wgpu::Device,
    pipeline: &wgpu::ComputePipeline,
    group: u32,
    entries: &[(u32, wgpu::BindingResource)],
) -> (u32, wgpu::BindGroup) {
    let entries: Vec<wgpu::BindGroupEntry> = entries
        .iter()
        .map(|(binding, r)| wgpu::BindGroupEntry {
            binding: *binding,
            resource: r.clone(),
        })
        .collect();
    let g = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("points test"),
        layout: &pipeline.get_bind_group_layout(group),
        entries: &entries,
    });
    (group, g)
}
