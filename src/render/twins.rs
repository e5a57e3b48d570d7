//! The Rust twins of WGSL declarations, checked against naga's reflection
//! of the assembled modules: every `#[repr(C)]` struct the shaders read
//! (member names in order, offsets and size), and the constants both sides
//! define.

use crate::gpu::pass::{PassSpec, Slots};
use crate::methods::raymarch::passes::{self as raymarch, BAKED, EXACT};
use crate::methods::slices::gpu::passes as slices;
use crate::methods::sprites::gpu::passes as sprites;

/// (size, [(member name, offset)]) of a Rust struct, its fields listed in
/// order; with the size, the list must cover every field to match WGSL.
macro_rules! rust_layout {
    ($ty:ty { $($field:ident),* $(,)? }) => {
        (
            std::mem::size_of::<$ty>(),
            vec![$((stringify!($field).to_string(), std::mem::offset_of!($ty, $field))),*],
        )
    };
}

/// (size, [(member name, offset)]) of WGSL struct `name` in `module`.
fn wgsl_layout(module: &naga::Module, name: &str) -> (usize, Vec<(String, usize)>) {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    let (handle, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no struct {name}"));
    let naga::TypeInner::Struct { members, .. } = &ty.inner else {
        panic!("{name} is not a struct");
    };
    let members = members
        .iter()
        .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
        .collect();
    (layouter[handle].size as usize, members)
}

pub(crate) fn module(pass: &PassSpec, slots: &Slots) -> naga::Module {
    let src = pass.source(slots);
    naga::front::wgsl::parse_str(&src).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&src)))
}

/// Asserts that WGSL struct `wgsl` of `module` is laid out as `rust`.
fn check(module: &naga::Module, wgsl: &str, rust: (usize, Vec<(String, usize)>)) {
    assert_eq!(
        wgsl_layout(module, wgsl),
        rust,
        "WGSL {wgsl} against its Rust twin"
    );
}

#[test]
fn frame_parcels_and_grid_match_pack_rs() {
    use crate::gpu::uniform::{CameraPos, FrameNoise, FrameUniform};
    use crate::methods::raymarch::pack::{GpuParcel, GridUniform, ParcelsUniform};
    use bytemuck::Zeroable;
    let m = module(&raymarch::CLOUDS, &EXACT);
    check(
        &m,
        "Frame",
        rust_layout!(FrameUniform {
            clip_from_world,
            eye_from_clip,
            camera_pos,
            sun_dir,
            phase_g,
            sun_color,
            exposure,
            step_m,
            max_steps,
            light_steps,
            light_step_m,
            noise_amplitude,
            shell_m,
            extinction_per_m,
            early_exit_transmittance,
            noise,
            grid_min,
            _pad0,
            grid_cell,
            _pad1,
            grid_dims,
            parcel_count,
            shadow_min,
            shadow_max,
            sky_ambient,
            sky_mie_g,
            sky_below,
            _pad2,
            sky_view,
            air,
        }),
    );
    // Two members are structs in WGSL and their bytes in Rust.
    let f = FrameUniform::zeroed();
    assert_eq!(size_of_val(&f.camera_pos), size_of::<CameraPos>());
    assert_eq!(size_of_val(&f.noise), size_of::<FrameNoise>());
    check(&m, "CameraPos", rust_layout!(CameraPos { eye_m, time_s }));
    check(
        &m,
        "FrameNoise",
        rust_layout!(FrameNoise {
            inv_scale_per_m,
            octaves,
            _pad,
            texels_per_m,
        }),
    );
    check(
        &m,
        "Parcel",
        rust_layout!(GpuParcel {
            center_m,
            radius_m,
            fill,
            plane_z_m,
            _pad,
        }),
    );
    check(&m, "Parcels", rust_layout!(ParcelsUniform { parcels }));
    check(&m, "Grid", rust_layout!(GridUniform { cells, entries }));
}

#[test]
fn temporal_uniform_matches() {
    use crate::methods::raymarch::temporal::TemporalUniform;
    let rust = || {
        rust_layout!(TemporalUniform {
            prev_clip_from_eye,
            offset,
            frame_index,
            history_valid,
            size,
            fresh,
            block,
            _pad0,
            _pad1,
            _pad2,
        })
    };
    check(&module(&raymarch::CLOUDS, &BAKED), "Temporal", rust());
    check(&module(&raymarch::TEMPORAL, &BAKED), "Temporal", rust());
}

#[test]
fn slices_structs_match() {
    use crate::methods::slices::gpu::SlicesParams;
    use crate::methods::slices::gpu::buffers::GpuPrimitive;
    use crate::methods::slices::gpu::gpu_field::{FieldJob, StackJob};
    use crate::methods::slices::model::octaves::{OctaveUniform, TierUniform};
    let m = module(&slices::SLICES, &slices::SLOTS);
    check(
        &m,
        "SlicesTier",
        rust_layout!(TierUniform {
            texture_from_world,
            bottom_m,
            first_weight,
            media,
            _pad,
        }),
    );
    check(
        &m,
        "SlicesOctaves",
        rust_layout!(OctaveUniform {
            tiers,
            tier_count,
            octave_count,
            _pad,
        }),
    );
    check(
        &m,
        "SlicesParams",
        rust_layout!(SlicesParams {
            sharpness,
            _pad2,
            _pad3,
            _pad4,
            cloud_colour,
            _pad0,
            shadow_colour,
            _pad1,
            index_min,
            cells_per_axis,
            index_cell,
            shadow_extinction_per_m,
        }),
    );
    check(
        &m,
        "Primitive",
        rust_layout!(GpuPrimitive {
            row0,
            strength,
            row1,
            base_z_m,
            row2,
            _pad0,
            centre_m,
            _pad1,
        }),
    );
    check(
        &module(&slices::SLICE_FIELD, &slices::SLOTS),
        "FieldJob",
        rust_layout!(FieldJob {
            vertices,
            rays,
            stack_count,
            first_octave,
            stacks,
        }),
    );
    check(
        &module(&slices::SLICE_FIELD, &slices::SLOTS),
        "StackJob",
        rust_layout!(StackJob {
            first_vertex,
            end_vertex,
            first_ray,
            end_ray,
            ray_stride,
            ray_offset,
            vertex_step,
            ray_vertices,
            shadow_step,
            first_primitive,
            end_primitive,
            _pad,
        }),
    );
}

#[test]
fn sprite_instance_matches() {
    use crate::methods::sprites::gpu::SpriteInstance;
    check(
        &module(&sprites::SPRITES, &sprites::SLOTS),
        "SpriteInstance",
        rust_layout!(SpriteInstance {
            corners,
            colors,
            sun,
            sky,
            uv
        }),
    );
}

#[test]
fn artist_light_gains_match() {
    use crate::methods::sprites::model::shading::{
        ARTIST_ADAPT_FLOOR, ARTIST_SKY_GAIN, ARTIST_SUN_GAIN, ARTIST_WHITE,
    };
    let m = module(&sprites::SPRITES, &sprites::SLOTS);
    for (name, v) in [
        ("ARTIST_SUN_GAIN", ARTIST_SUN_GAIN),
        ("ARTIST_SKY_GAIN", ARTIST_SKY_GAIN),
        ("ARTIST_WHITE", ARTIST_WHITE),
        ("ARTIST_ADAPT_FLOOR", ARTIST_ADAPT_FLOOR),
    ] {
        assert_eq!(wgsl_const(&m, name), v as f64, "{name}");
    }
}

/// The value of WGSL constant `name` in `module`.
pub(crate) fn wgsl_const(module: &naga::Module, name: &str) -> f64 {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no const {name}"));
    match module.global_expressions[c.init] {
        naga::Expression::Literal(naga::Literal::F32(v)) => v as f64,
        naga::Expression::Literal(naga::Literal::U32(v)) => v as f64,
        naga::Expression::Literal(naga::Literal::I32(v)) => v as f64,
        ref e => panic!("{name} = {e:?} is not a literal"),
    }
}

#[test]
fn clipmap_levels_match_clipmap_rs() {
    use crate::methods::raymarch::clipmap::{ClipUniform, GpuClipLevel};
    let m = module(&raymarch::CLOUDS, &BAKED);
    check(
        &m,
        "ClipLevel",
        rust_layout!(GpuClipLevel {
            min_voxel,
            cells,
            offsets
        }),
    );
    check(&m, "Clipmap", rust_layout!(ClipUniform { count, levels }));
}

#[test]
fn constants_shared_with_rust_match() {
    use crate::methods::raymarch::baked;
    let bake = {
        let src = crate::gpu::shaders::assemble_with("raymarch/bake.wgsl", &[], &BAKED)
            .unwrap()
            .source;
        naga::front::wgsl::parse_str(&src).unwrap()
    };
    assert_eq!(wgsl_const(&bake, "BAKE_BLOCK"), baked::BAKE_BLOCK as f64);
    assert_eq!(wgsl_const(&bake, "SPLAT_ROW"), baked::SPLAT_ROW as f64);
    assert_eq!(wgsl_const(&bake, "KEY_SPLIT"), baked::KEY_SPLIT as f64);
    assert_eq!(
        wgsl_const(&bake, "MAX_CLIP_LEVELS"),
        crate::methods::raymarch::clipmap::MAX_CLIP_LEVELS as f64
    );
    assert_eq!(
        wgsl_const(&bake, "OCCUPANCY_LEVELS"),
        baked::OCCUPANCY_LEVELS as f64
    );
    assert_eq!(
        wgsl_const(&bake, "OCCUPANCY_FACTOR"),
        baked::OCCUPANCY_FACTOR as f64
    );
    assert_eq!(wgsl_const(&bake, "PLANE_SHELL"), baked::PLANE_SHELL as f64);
    assert_eq!(
        wgsl_const(&bake, "PLANE_SHELL"),
        crate::methods::raymarch::field::PLANE_SHELL as f64
    );
    // The array sizes of the parcel and grid uniforms.
    use crate::methods::raymarch::pack::{MAX_GRID_CELLS, MAX_GRID_ENTRIES, MAX_PARCELS};
    let exact = module(&raymarch::CLOUDS, &EXACT);
    assert_eq!(wgsl_const(&exact, "MAX_PARCELS"), MAX_PARCELS as f64);
    assert_eq!(wgsl_const(&bake, "MAX_PARCELS"), MAX_PARCELS as f64);
    assert_eq!(
        wgsl_const(&exact, "GRID_CELL_PAIRS"),
        (MAX_GRID_CELLS / 2) as f64
    );
    assert_eq!(
        wgsl_const(&exact, "GRID_ENTRY_QUADS"),
        (MAX_GRID_ENTRIES / 4) as f64
    );
    // The stack table of the slices' vertex-field job.
    let field = module(&slices::SLICE_FIELD, &slices::SLOTS);
    assert_eq!(
        wgsl_const(&field, "MAX_STACKS"),
        crate::methods::slices::model::MAX_STACKS as f64
    );
}
