// The `exact` method's far light (the `<far_light>` slot; the `baked`
// method reads a light volume instead, field_baked.wgsl): the optical
// depths of the parcels alone (no noise; density × m) from P to the cloud
// region's edge, marched through the field by far_depth_along
// (density.wgsl) at a step of one grid cell's shortest side:
//   far_light_depth(p)      toward the sun (x) and straight up (y)
//   far_behind_depth(p)     away from the sun

#import "../common.wgsl"
#import "density.wgsl"

// The march's step: one grid cell's shortest side. units: m
fn far_step() -> f32 {
    let cell = frame.grid_cell;
    return min(cell.x, min(cell.y, cell.z));
}

// Optical depths (density × m) of the parcels alone from P to the grid
// box's edge toward the sun (x) and straight up (y).
fn far_light_depth(p: vec3<f32>) -> vec2<f32> {
    let ds = far_step();
    return vec2<f32>(far_depth_along(p, frame.sun_dir, ds), far_depth_along(p, vec3<f32>(0.0, 0.0, 1.0), ds));
}

// The same away from the sun.
fn far_behind_depth(p: vec3<f32>) -> f32 {
    return far_depth_along(p, -frame.sun_dir, far_step());
}
