// Shared by every ravh_sim shader: hashing, value noise and the outdoor backdrop.
const float PI = 3.14159265;

float hash12(vec2 p) {
    vec3 p3 = fract(vec3(p.xyx) * 0.1031);
    p3 += dot(p3, p3.yzx + 33.33);
    return fract((p3.x + p3.y) * p3.z);
}

float hash13(vec3 p) {
    p = fract(p * 0.1031);
    p += dot(p, p.zyx + 31.32);
    return fract((p.x + p.y) * p.z);
}

// Value noise from a tiling 3D texture (see materials.noise_volume): channel r has one lattice cell
// per unit of p, g, b and a twice, four and eight times finer. One filtered fetch replaces eight
// hashes per octave, which is what makes procedural materials affordable on a CPU rasteriser.
uniform sampler3D u_noise;

float vnoise(vec3 p) {
    return texture(u_noise, p * 0.125).r;
}

float fbm(vec3 p) {
    return dot(texture(u_noise, p * 0.125), vec4(0.5333, 0.2667, 0.1333, 0.0667));
}

// Detail finer than a pixel or two: one hash per cell, no texture fetch (a fetch at that frequency
// misses the cache on every pixel).
float grain(vec3 p) {
    return hash13(floor(p));
}

// The world outside the windows, seen along unit direction d from the house: a sky with the sun's
// glow, a horizon of trees and house fronts on a ring around the house, and the ground.
uniform vec3 u_sky_zenith;
uniform vec3 u_sky_horizon;
uniform vec3 u_ground;
uniform vec3 u_sun_dir;
uniform vec3 u_sun_radiance;
uniform vec3 u_facade;

vec3 outdoor(vec3 d) {
    float azimuth = atan(d.y, d.x);
    float elevation = asin(clamp(d.z, -1.0, 1.0));
    // Skyline: tree crowns (rounded, noisy) and flat-topped house fronts, 6-14 degrees high.
    float crowns = 0.10 + 0.08 * fbm(vec3(azimuth * 9.0, 0.0, 3.0)) + 0.03 * vnoise(vec3(azimuth * 40.0, 1.0, 0.0));
    float block = floor(azimuth * 6.0);
    float facade = hash12(vec2(block, 2.0)) < 0.45 ? 0.07 + 0.09 * hash12(vec2(block, 5.0)) : 0.0;
    float skyline = max(crowns, facade);
    if (elevation > skyline) {
        float t = pow(clamp(elevation / 1.2, 0.0, 1.0), 0.45);
        vec3 sky = mix(u_sky_horizon, u_sky_zenith, t);
        float clouds = smoothstep(0.55, 0.8, fbm(vec3(d.xy / max(d.z, 0.05) * 1.5, 7.0)));
        sky = mix(sky, mix(u_sky_horizon, vec3(dot(u_sky_zenith, vec3(0.33))) * 1.4, 0.5), clouds * 0.6);
        float glow = max(dot(d, u_sun_dir), 0.0);
        return sky + u_sun_radiance * (0.02 * pow(glow, 8.0) + 0.6 * pow(glow, 2000.0));
    }
    if (elevation > 0.0) {
        if (facade > crowns && elevation < facade) {
            float win = step(0.5, fract(azimuth * 180.0)) * step(0.45, fract(elevation * 90.0));
            return u_facade * (0.85 + 0.3 * hash12(vec2(block, 9.0))) * (1.0 - 0.45 * win);
        }
        float leaf = fbm(vec3(azimuth * 60.0, elevation * 60.0, 1.0));
        return u_ground * vec3(0.55, 0.8, 0.45) * (0.5 + 0.6 * leaf);
    }
    // Ground: grass and paths fading to haze in the distance.
    vec2 at = d.xy / max(-d.z, 0.02) * 1.5;
    float grass = 0.75 + 0.5 * fbm(vec3(at * 2.0, 4.0));
    float haze = exp(elevation * 25.0);
    float path = smoothstep(0.45, 0.5, vnoise(vec3(at * 0.3, 9.0)));
    vec3 ground = mix(u_ground * grass, u_facade * 0.45, path * 0.35);
    return mix(ground, u_sky_horizon * 0.7, haze * 0.35);
}

// Daylight through the windows of a surface's room: each window an area light of the outdoors'
// mean radiance, its irradiance the on-axis disc form factor A cos_w cos_n / (d^2 + A / pi), so
// light falls off away from the windows and surfaces turned to them are brighter than those
// turned away (form shading). Windows of other rooms are walled off: ``span`` packs the room's
// first window and their count (GLRenderer's WINDOW_SPAN), so a pixel visits only its own.
uniform vec4 u_window_centre[MAX_WINDOWS];    // xyz
uniform vec4 u_window_normal[MAX_WINDOWS];    // unit normal into the room, area in m^2
uniform vec3 u_window_radiance;

vec3 window_light(vec3 p, vec3 n, float span) {
    int code = int(span + 0.5);
    int first = code % WINDOW_SPAN;
    float irradiance = 0.0;
    for (int i = first; i < first + code / WINDOW_SPAN; ++i) {
        vec3 d = u_window_centre[i].xyz - p;
        float d2 = max(dot(d, d), 1e-4);
        vec3 l = d * inversesqrt(d2);
        float area = u_window_normal[i].w;
        irradiance += max(dot(n, l), 0.0) * max(-dot(u_window_normal[i].xyz, l), 0.0) * area / (d2 + area / PI);
    }
    return u_window_radiance * irradiance;
}

float luminance(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

// The camera response shared by the renderer's own tone map and the sensor's development:
// Narkowicz's ACES fit (linear in, display-linear [0, 1] out) and the sRGB transfer curve.
vec3 aces(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 srgb_encode(vec3 c) {
    return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
