// The artist's colour contract of the authored methods (Wang 2003's colour
// levels and time-of-day tables, Schpok 2003's cloud colours): an artist
// paints a colour as it should look (sRGB-encoded, 0.2 a dark cloud base,
// 1.0 a sunlit white top) and says how much of the sky's and of the sun's
// light reaches that point; the frame supplies the light itself, from the
// atmosphere model (frame.sun_color, frame.sky_ambient): its colour (red at
// a low sun) and the balance of sun and sky are the frame's, the same light
// the ray-marched clouds and the terrain get. Its strength is adapted as an
// eye adapts: the full light is brought to the strength of a high sun's
// (ARTIST_WHITE) down to a third of it (deep dusk, night: darker). So a
// painted colour keeps its meaning at noon and at dusk, under the frame's
// exposure and tone curve.
// CPU twin: `shading::artist_light` in src/methods/sprites/model/shading.rs
// (src/render/twins.rs checks its constants; tests/cumulus/sprites/look.rs
// the contract in the written PNG).

#import "common.wgsl"

// A thick cloud's sunlit side reflects about like a white Lambertian
// surface of albedo 0.75 facing the sun: the sun's irradiance is
// 4π·sun_color (the march's source term), so its radiance is
// 0.75·4π·sun_color/π = 3·sun_color.
const ARTIST_SUN_GAIN: f32 = 3.0;
// Its shaded side sees the sky like a white Lambertian surface:
// radiance = sky irradiance / π = sky_ambient.
const ARTIST_SKY_GAIN: f32 = 1.0;

// Luminance of the full light (sky + sun, gains above) under a sun 45–50°
// high in clear air (6.7 at 48°, 7.4 overhead with the shipped atmosphere):
// the strength a painted colour is meant at.
const ARTIST_WHITE: f32 = 6.5;
// The light is brought to ARTIST_WHITE from this fraction of it up: a sun
// 10° high (a third of a high sun's light) still lights a white top white;
// below, the light fades with the frame's.
const ARTIST_ADAPT_FLOOR: f32 = 0.3;

// The sRGB decoding (IEC 61966-2-1), encoded [0, 1] to linear.
fn srgb_decode(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((max(c, vec3<f32>(0.0)) + 0.055) / 1.055, vec3<f32>(2.4));
    return select(hi, lo, c <= vec3<f32>(0.04045));
}

// Linear radiance of a painted colour `painted` (sRGB-encoded) that
// receives the share `sky` of the sky's light and `sun` of the sun's.
fn artist_light(painted: vec3<f32>, sky: f32, sun: f32) -> vec3<f32> {
    let sky_light = ARTIST_SKY_GAIN * frame.sky_ambient;
    let sun_light = ARTIST_SUN_GAIN * frame.sun_color;
    let full = dot(sky_light + sun_light, vec3<f32>(0.2126, 0.7152, 0.0722));
    let adapt = ARTIST_WHITE / max(full, ARTIST_ADAPT_FLOOR * ARTIST_WHITE);
    return srgb_decode(painted) * (sky * sky_light + sun * sun_light) * adapt;
}
