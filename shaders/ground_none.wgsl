// The `<ground_shadow>` slot of a method that marches no shadow (the
// sprites, which splat theirs into the map): no cloud along the sun ray.
// The terrain imports the slot for its in-region march, which such a
// method switches off (SHADOW_IN_REGION false).

fn ground_sun_depth(p: vec3<f32>) -> f32 {
    return 0.0;
}
