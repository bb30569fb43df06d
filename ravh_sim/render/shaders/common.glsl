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

// The four octaves of one fetch apart, for a shader that wants a shape and its detail from one fetch.
vec4 octaves(vec3 p) {
    return texture(u_noise, p * 0.125);
}

// Detail finer than a pixel or two: one hash per cell, no texture fetch (a fetch at that frequency
// misses the cache on every pixel).
float grain(vec3 p) {
    return hash13(floor(p));
}

// The world outside the windows, along unit direction d from o (any point on the ray: the camera,
// or the glass it looks through). The neighbourhood stands on rings around the house (u_site: its
// bounds, centre xy and half extents) and is hit by the ray, not looked up by direction, so it has
// depth: the lawn recedes in perspective, a hedge, trees and the neighbours' houses stand at their
// own distances and shift against each other as the camera moves. u_outdoor_seed picks the house's own.
uniform vec3 u_sky_zenith;
uniform vec3 u_sky_horizon;
uniform vec3 u_sun_dir;
uniform vec3 u_sun_radiance;
uniform vec3 u_outdoor_light;       // the sun (moon) on a surface facing it
uniform vec3 u_outdoor_fill;        // the sky's light on an upward surface
uniform vec3 u_lit_windows;         // a neighbour's lit window
uniform vec4 u_site;
uniform float u_ground_z;
uniform float u_outdoor_seed;

// Light on an outdoor surface of albedo a and normal n: sun, sky, and the sunlit ground's bounce
// (what keeps a wall in shade from turning sky blue); and the haze of distance t.
vec3 lit(vec3 a, vec3 n, float sunlit) {
    vec3 bounce = u_outdoor_light * (0.04 * max(u_sun_dir.z, 0.0) * (1.0 - n.z));
    return a * (u_outdoor_light * max(dot(n, u_sun_dir), 0.0) * sunlit + u_outdoor_fill * (0.55 + 0.45 * n.z)
                + bounce);
}

vec3 hazed(vec3 c, float t) {
    return mix(c, u_sky_horizon, 1.0 - exp(-t / 900.0));
}

// Distance along d from o to the ring of radius r around the site (o inside it).
float ring(vec3 o, vec3 d, float r) {
    vec2 q = o.xy - u_site.xy;
    float a = max(dot(d.xy, d.xy), 1e-6);
    float b = dot(q, d.xy);
    return (-b + sqrt(max(b * b - a * (dot(q, q) - r * r), 0.0))) / a;
}

vec3 sky(vec3 o, vec3 d) {
    float up = max(d.z, 0.0);
    vec3 c = mix(u_sky_horizon, u_sky_zenith, pow(up, 0.5));
    float toward = max(dot(d, u_sun_dir), 0.0);
    vec3 sun_colour = u_outdoor_light / max(max(u_outdoor_light.r, u_outdoor_light.g), 1e-4);
    // Clouds: a deck 1.5 km up, thinning to the horizon; sunlit through their thin parts.
    vec2 at = (o.xy + d.xy * (1500.0 / max(d.z, 0.03))) / 900.0 + u_outdoor_seed * 97.0;
    float density = fbm(vec3(at, 7.0 + u_outdoor_seed * 5.0));
    float cover = 0.42 + 0.2 * fract(u_outdoor_seed * 13.7);
    float cloud = smoothstep(cover, cover + 0.22, density) * smoothstep(0.0, 0.12, d.z);
    if (cloud > 0.0) {
        float edge = 1.0 - smoothstep(cover, cover + 0.35, density);
        vec3 cc = u_outdoor_fill * 0.7 + u_outdoor_light * (0.25 + 0.35 * edge + 0.6 * pow(toward, 6.0));
        c = mix(c, cc, cloud * 0.9);
    }
    // The sun's glow (wide at dusk, when the light is low and warm) and its disc.
    c += sun_colour * dot(u_sky_horizon, vec3(0.33)) * (0.35 * pow(toward, 6.0) + 0.25 * pow(toward, 40.0));
    c += u_sun_radiance * 0.6 * pow(toward, 2000.0);
    // A few stars on a dark night.
    float dark = 1.0 - smoothstep(0.002, 0.02, dot(u_sky_zenith, vec3(0.33)));
    if (dark > 0.0) {
        vec2 cell = floor(d.xy / max(d.z, 0.05) * 300.0);
        c += dark * step(0.997, hash12(cell)) * 0.02 * smoothstep(0.1, 0.3, d.z);
    }
    return c;
}

vec3 outdoor_at(vec3 o, vec3 d) {
    float seed = u_outdoor_seed;
    float ground_z = u_ground_z;
    float house = length(u_site.zw);
    float t_ground = d.z < 0.0 ? (ground_z - o.z) / d.z : 1e9;

    // Each layer is tested only where the ray passes low enough to meet it (the height check comes
    // before the angle and the noise: most of a window is sky or lawn).
    // A hedge (or a fence) round the garden, with gaps.
    float r1 = house + 5.0 + 7.0 * fract(seed * 7.3);
    float t = ring(o, d, r1);
    vec3 p = o + d * t;
    float h = p.z - ground_z;
    if (t < t_ground && h < 2.1) {
        float s = atan(p.y - u_site.y, p.x - u_site.x) * r1;
        float section = floor(s / 9.0);
        float kind = hash12(vec2(section, seed * 91.0));
        float top = 1.1 + 0.7 * hash12(vec2(section, seed * 17.0)) + 0.1 * sin(s * 1.7) + 0.06 * sin(s * 4.3 + seed);
        if (kind > 0.15 && h < top) {
            vec3 n = normalize(vec3(u_site.xy - p.xy, 0.0));
            if (kind < 0.55) {              // a fence of boards
                float board = fract(s * 6.0);
                vec3 wood = vec3(0.32, 0.22, 0.13) * (0.7 + 0.5 * hash12(vec2(floor(s * 6.0), section)));
                return hazed(lit(wood * (0.6 + 0.4 * step(0.12, board)), n, 1.0), t);
            }
            // Clumps, and leaves where they are big enough to see (closer than ~25 m).
            vec4 n4 = octaves(vec3(s * 2.5, h * 2.5, seed * 30.0));
            float leaf = dot(n4.rgb, vec3(0.57, 0.29, 0.14)) + 0.45 * (n4.a - 0.5) * (1.0 - smoothstep(12.0, 25.0, t));
            vec3 green = vec3(0.05, 0.1, 0.03) * (0.45 + 1.1 * leaf);
            return hazed(lit(green, normalize(n + vec3(0.0, 0.0, (h / top) - 0.3)), 0.5 + 0.7 * leaf), t);
        }
    }

    // Trees at the neighbours' gardens: round crowns of varied size on trunks, sunlit on one side.
    float r2 = r1 + 6.0 + 10.0 * fract(seed * 3.1);
    t = ring(o, d, r2);
    p = o + d * t;
    h = p.z - ground_z;
    if (t < t_ground && h < 17.0) {
        float s = atan(p.y - u_site.y, p.x - u_site.x) * r2;
        float width = 7.0;
        float cell = floor(s / width);
        float best = -1.0;
        vec3 colour = vec3(0.0);
        for (int k = 0; k < 2; ++k) {
            float c = cell + (k == 0 ? 0.0 : (fract(s / width) < 0.5 ? -1.0 : 1.0));
            float there = hash12(vec2(c, seed * 41.0));        // one hash, several numbers
            if (there > 0.3 + 0.35 * fract(seed * 5.9)) continue;
            vec3 pick = fract(there * vec3(97.13, 131.7, 173.9));
            float radius = 2.0 + 2.8 * pick.x;
            vec2 centre = vec2((c + 0.3 + 0.4 * pick.y) * width, radius * 0.8 + 1.5 + 4.0 * pick.z);
            vec2 q = (vec2(s, h) - centre) / radius;
            q.y *= 1.0 - 0.25 * fract(there * 211.3);             // some crowns taller than wide
            float r = length(q);
            vec4 n4 = r < 1.12 ? octaves(vec3(s * 0.9, h * 0.9, c)) : vec4(0.0);   // outline and leaves
            float edge = r < 1.12 ? 0.82 + 0.3 * n4.r : 0.0;
            if (r < edge) {
                float depth = sqrt(max(1.0 - r * r / (edge * edge), 0.0));
                if (depth <= best) continue;
                best = depth;
                vec3 radial = normalize(vec3(p.xy - u_site.xy, 0.0));
                vec3 tangent = vec3(-radial.y, radial.x, 0.0);
                vec3 n = normalize(tangent * q.x + vec3(0.0, 0.0, q.y) - radial * depth);
                float leaf = dot(n4.gba, vec3(0.57, 0.29, 0.14));
                vec3 tint = mix(vec3(0.05, 0.09, 0.025), vec3(0.09, 0.1, 0.03), fract(there * 257.1));
                colour = lit(tint * (0.5 + leaf), n, smoothstep(0.35, 0.6, leaf + 0.3 * depth));
            } else if (best < 0.0 && abs(s - centre.x) < 0.12 + 0.05 * radius && h < centre.y) {
                best = 0.0;
                colour = lit(vec3(0.07, 0.05, 0.035), -normalize(vec3(p.xy - u_site.xy, 0.0)), 0.5);
            }
        }
        if (best >= 0.0) return hazed(colour, t);
    }

    // The neighbours' houses: rendered or brick fronts, gabled or hipped roofs, rows of windows
    // (dark glass by day, some lit at night).
    float r3 = r2 + 12.0 + 15.0 * fract(seed * 11.3);
    t = ring(o, d, r3);
    p = o + d * t;
    h = p.z - ground_z;
    if (t < t_ground && h < 12.0) {
        float s = atan(p.y - u_site.y, p.x - u_site.x) * r3;
        float plot = 16.0;
        float cell = floor(s / plot);
        float x = s - cell * plot;
        float w = 8.0 + 6.0 * hash12(vec2(cell, seed * 61.0));
        float x0 = (plot - w) * hash12(vec2(cell, seed * 67.0));
        float floors = 1.0 + floor(2.99 * hash12(vec2(cell, seed * 71.0)));
        float eave = floors * 2.8 + 0.4;
        float u = (x - x0) / w;
        float gable = hash12(vec2(cell, seed * 73.0));
        float roof = gable < 0.5 ? 3.2 * (1.0 - abs(2.0 * u - 1.0)) : 2.4 * min(1.0, min(u, 1.0 - u) * 5.0);
        if (hash12(vec2(cell, seed * 79.0)) < 0.85 && u > 0.0 && u < 1.0 && h < eave + roof) {
            vec3 n = normalize(vec3(u_site.xy - p.xy, 0.0));
            if (h > eave) {
                vec3 tiles = hash12(vec2(cell, 83.0)) < 0.5 ? vec3(0.28, 0.1, 0.06) : vec3(0.1, 0.1, 0.11);
                float course = 0.75 + 0.25 * step(0.2, fract(h * 3.0));
                return hazed(lit(tiles * course, normalize(n + vec3(0.0, 0.0, 1.2)), 1.0), t);
            }
            float pick = hash12(vec2(cell, seed * 89.0));
            vec3 wall = pick < 0.3 ? vec3(0.7, 0.68, 0.62) : pick < 0.55 ? vec3(0.72, 0.62, 0.44)
                      : pick < 0.8 ? vec3(0.42, 0.2, 0.13) : vec3(0.5, 0.5, 0.48);
            // Windows: 1.2 m wide every 2.6 m, 1.3 m tall on each floor; a thin light frame.
            float wx = x - x0 - 1.0;
            float column = floor(wx / 2.6);
            float level = floor((h - 0.4) / 2.8);
            vec2 in_win = vec2(fract(wx / 2.6) * 2.6, h - 0.4 - level * 2.8 - 1.0);
            bool window = wx > 0.0 && wx < w - 2.0 && in_win.x < 1.2 && in_win.y > 0.0 && in_win.y < 1.3;
            vec3 c = lit(wall, n, 1.0);
            if (window) {
                bool frame = in_win.x < 0.07 || in_win.x > 1.13 || in_win.y < 0.07 || in_win.y > 1.23;
                float on = step(hash12(vec2(column + cell * 17.0, level + seed * 13.0)), 0.3);
                vec3 glass = u_sky_horizon * 0.12 + u_lit_windows * on * (0.6 + 0.8 * hash12(vec2(column, level)));
                c = frame ? lit(vec3(0.75), n, 1.0) : glass;
            }
            return hazed(c, t);
        }
    }

    // A far treeline on the horizon, blue with distance.
    if (d.z >= 0.0 || t_ground > 260.0) {
        if (d.z < 17.0 / 260.0) {
            float far = (3.0 + 14.0 * fbm(vec3(atan(d.y, d.x) * 12.0, seed * 20.0, 3.0))) / 260.0;
            if (d.z < far) return hazed(lit(vec3(0.05, 0.08, 0.03), vec3(0.0, 0.0, 1.0), 0.6), 260.0 * 1.6);
        }
        return sky(o, d);
    }

    // The ground: lawn with mown stripes and patches, a paved terrace round the house; detail
    // fades with distance (it would alias).
    p = o + d * t_ground;
    vec2 g = p.xy - u_site.xy;
    float fade = 1.0 - smoothstep(8.0, 35.0, t_ground);
    vec3 c;
    vec2 beyond = abs(g) - u_site.zw;
    if (max(beyond.x, beyond.y) < 1.8 + 0.8 * fract(seed * 19.0)) {
        vec2 tile = fract(p.xy / 0.6);
        float joint = step(0.05, tile.x) * step(0.05, tile.y);
        c = vec3(0.2, 0.18, 0.16) * (0.75 + 0.25 * mix(1.0, joint, fade) + 0.2 * hash12(floor(p.xy / 0.6)) * fade);
    } else {
        vec4 n4 = octaves(vec3(p.xy * 0.4, seed * 40.0));
        float patches = dot(n4.rgb, vec3(0.57, 0.29, 0.14));
        float fine = mix(0.5, n4.a, fade);
        float stripe = 0.07 * fade * step(0.5, fract(dot(g, vec2(0.8, 0.6)) / 1.4));
        c = vec3(0.07, 0.12, 0.035) * (0.65 + 0.7 * patches + 0.3 * fine + stripe);
    }
    return hazed(lit(c, vec3(0.0, 0.0, 1.0), 1.0), t_ground);
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
