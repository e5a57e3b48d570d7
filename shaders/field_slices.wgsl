// The `slices` method's cloud density for the cloud-shadow map
// (shadow.wgsl): the field the slicing planes draw, Σ Wyvill blends of the
// authored ellipsoids and the parcels' spheres (flat at their condensation
// planes) × the media filter of the noise octaves (implicit.wgsl), scaled
// so that shadow.wgsl's exp(−Σ density · ds · extinction) is the slices'
// optical depth along the sun ray (params.index_cell.w, see
// SlicesParams::new in src/render/slices/mod.rs).

fn cloud_density(p: vec3<f32>) -> f32 {
    let f = implicit_field(p);
    if f <= 0.0 {
        return 0.0;
    }
    return f * media_at(p) * params.index_cell.w / frame.cloud.z;
}
