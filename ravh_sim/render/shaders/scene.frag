// Physically based shading of one surface point: procedural material, the sun with filtered
// shadow-map look-ups, lamps with inverse-square fall-off and cube shadow maps, per-room sky and
// bounce light with ambient occlusion, window glass that shows the outdoors, emissive fixtures.
// Writes HDR colour (alpha: log luminance, for auto-exposure), z-depth in metres and the instance id.
// Compiled once per pattern (PATTERN_ID): a CPU rasteriser runs every branch of a shader, so each
// material group is drawn by a program that holds only its own pattern.
in vec3 v_world;
in vec3 v_normal;
in vec3 v_local;
in float v_eye_z;
in vec2 v_uv;
flat in int v_material;
flat in int v_instance;
layout(location = 0) out vec4 out_hdr;
layout(location = 1) out float out_depth;
layout(location = 2) out int out_instance;

uniform sampler2D u_materials;        // TEXELS x materials
uniform sampler2DArray u_library;     // library models' textures, one layer each (sRGB)
uniform sampler2D u_instances;        // instances x 3: room, emission+kind, floor/ceiling z
uniform sampler2D u_room_map;         // floor plan: room index + 1 per cell, 0 outside
uniform vec4 u_room_box;              // x0, y0, 1/width, 1/height in metres
uniform sampler2D u_room_light;       // rooms x 1: sky and bounce light of each room
uniform sampler2DShadow u_sun_shadow;
uniform sampler2DShadow u_point_shadow;  // atlas: 6 faces per row, one row per shadowed lamp (distance
                                         // over LAMP_SHADOW_RANGE), bilinear 2 x 2 comparisons
uniform sampler2D u_coverage;         // blurred top-down coverage (ambient occlusion on floors)
uniform mat4 u_sun_matrix;
uniform vec3 u_sun_irradiance;
uniform vec4 u_coverage_box;          // x0, y0, 1/width, 1/height in metres
uniform vec3 u_eye;
uniform vec4 u_light_position[MAX_LIGHTS];   // xyz, range
uniform vec4 u_light_power[MAX_LIGHTS];      // rgb, shadow row (-1: none; then confined to its room)
uniform int u_room_lights[MAX_ROOMS];        // the frame's lights reaching each room (its own, open doors):
                                             // bits 0-3 their count, then 3 bits per light index
uniform vec2 u_atlas_texels;                 // atlas size in texels
uniform float u_tile;                        // texels per cube face
uniform int u_shadows;                       // realistic quality: shadows on
uniform sampler2D u_probes;                  // room probes: 6 faces per row, one row per room
uniform sampler2D u_probe_boxes;             // rooms x 3: box min, box max, probe centre
uniform vec2 u_probe_texels;
uniform float u_probe_tile;
uniform int u_probes_ready;                  // 0 while the probes themselves are rendered

struct Surface { vec3 albedo; float roughness; float metalness; float height; };

// Materials smooth enough to show their room's reflection (the others reflect a plain surround).
#define GLOSSY (PATTERN_ID == PATTERN_MIRROR || PATTERN_ID == PATTERN_METAL || PATTERN_ID == PATTERN_SCREEN \
    || PATTERN_ID == PATTERN_CERAMIC || PATTERN_ID == PATTERN_TILES || PATTERN_ID == PATTERN_MARBLE \
    || PATTERN_ID == PATTERN_PARQUET || PATTERN_ID == PATTERN_LEATHER)

vec3 face_normal_local() {
    return abs(normalize(cross(dFdx(v_local), dFdy(v_local))));
}

// Planar coordinates of a point on a face: the two axes the face spans.
vec2 planar(vec3 p, vec3 n) {
    return n.z > 0.7 ? p.xy : (n.x > n.y ? p.yz : p.xz);
}

Surface pattern(vec3 base, vec3 accent, float rough, float metal, float scale, float variation, vec3 p, float layer) {
    vec3 n = face_normal_local();
    vec2 uv = planar(p, n);
    Surface s = Surface(base, rough, metal, 0.0);
#if PATTERN_ID == PATTERN_WOOD
    {
        float along = n.z > 0.7 ? p.x : p.z;
        float across = n.z > 0.7 ? p.y : (n.x > n.y ? p.y : p.x);
        float warp = 0.7 * fbm(vec3(along * 0.4, across * 2.0, 0.0));
        float ring = fract(across * scale + warp);
        float streak = 0.6 * vnoise(vec3(along * 2.0, across * 18.0, 3.0)) + 0.4 * grain(vec3(along * 40.0, across * 400.0, 3.0));
        float t = smoothstep(0.3, 0.9, ring) * 0.55 + 0.45 * streak;
        s.albedo = mix(base, accent, t * variation * 1.3);
        s.height = t;
    }
#elif PATTERN_ID == PATTERN_PARQUET
    {
        float width = 0.16 / scale, len = 1.2 / scale;
        float row = floor(uv.y / width);
        float shift = hash12(vec2(row, 7.0)) * len;
        float col = floor((uv.x + shift) / len);
        vec2 f = vec2(fract((uv.x + shift) / len) * len, fract(uv.y / width) * width);
        float id = hash12(vec2(row, col));
        float gap = min(min(f.x, len - f.x), min(f.y, width - f.y));
        float groove = smoothstep(0.0008, 0.0025, gap);
        float ring = fract((f.y + id) * 14.0 + 1.5 * fbm(vec3(f.x * 1.5, f.y * 6.0, id * 10.0)));
        float streak = 0.6 * vnoise(vec3(f.x * 3.0, f.y * 25.0, id * 20.0)) + 0.4 * grain(vec3(f.x * 40.0, f.y * 500.0, id * 20.0));
        float t = 0.6 * smoothstep(0.2, 0.9, ring) + 0.4 * streak;
        s.albedo = mix(base, accent, t * variation * 1.6) * (0.82 + 0.36 * id) * mix(0.3, 1.0, groove);
        s.roughness = mix(0.9, rough, groove);
        s.height = groove + 0.15 * t;
    }
#elif PATTERN_ID == PATTERN_TILES
    {
        float size = 1.0 / scale;
        vec2 c = uv / size;
        vec2 f = fract(c) * size;
        float gap = min(min(f.x, size - f.x), min(f.y, size - f.y));
        float tile = smoothstep(0.0015, 0.0035, gap);
        float id = hash12(floor(c) + 3.0);
        s.albedo = mix(accent, base * (0.95 + 0.1 * id) * (0.97 + 0.06 * vnoise(p * 6.0)), tile);
        s.roughness = mix(0.85, rough, tile);
        s.height = tile;
    }
#elif PATTERN_ID == PATTERN_MARBLE
    {
        float v = abs(sin(dot(p, vec3(1.0, 0.6, 0.3)) * scale * 2.0 + 5.0 * fbm(p * scale)));
        float vein = smoothstep(0.0, 0.05, v) * 0.7 + 0.3 * smoothstep(0.0, 0.3, v);
        s.albedo = mix(mix(base, accent, 0.6), base, mix(1.0, vein, variation * 2.5)) * (0.95 + 0.1 * fbm(p * 9.0));
        s.height = vein * 0.2;
    }
#elif PATTERN_ID == PATTERN_FABRIC
    {
        // The weave fades out where a thread pair spans more than about a pixel: drawn finer, it
        // aliased into moire across beds and sofas. Its average (t = 0.5) stays.
        vec2 footprint = fwidth(uv * scale);
        float resolved = clamp(1.5 - 1.5 * max(footprint.x, footprint.y), 0.0, 1.0);
        float weave = sin(uv.x * scale * PI) * sin(uv.y * scale * PI) * resolved;
        float t = 0.5 + 0.5 * weave;
        float mottle = fbm(p * 7.0);
        s.albedo = mix(accent, base, 0.7 + 0.3 * t) * (1.0 + (mottle - 0.5) * variation);
        s.height = t * 0.5 + 0.5 * grain(p * scale * 0.25) * resolved;
    }
#elif PATTERN_ID == PATTERN_LEATHER
    {
        float cell = vnoise(p * scale * 0.15);
        float crease = 1.0 - abs(cell * 2.0 - 1.0);
        s.albedo = base * (0.88 + 0.24 * fbm(p * 4.0)) * (1.0 - 0.15 * crease * variation * 4.0);
        s.roughness = rough + 0.15 * crease;
        s.height = crease;
    }
#elif PATTERN_ID == PATTERN_CARPET
    {
        float pile = grain(p * scale) * 0.5 + vnoise(p * 12.0) * 0.5;
        s.albedo = mix(accent, base, pile) * (0.9 + 0.2 * fbm(p * 1.5));
        s.height = pile;
    }
#elif PATTERN_ID == PATTERN_BRICK
    {
        vec2 b = vec2(uv.x, uv.y) / vec2(0.24, 0.075);
        float row = floor(b.y);
        b.x += 0.5 * mod(row, 2.0);
        vec2 f = fract(b) * vec2(0.24, 0.075);
        float gap = min(min(f.x, 0.24 - f.x), min(f.y, 0.075 - f.y));
        float brick = smoothstep(0.004, 0.007, gap);
        float id = hash12(floor(b) + 11.0);
        s.albedo = mix(accent, base * (0.8 + 0.4 * id) * (0.9 + 0.2 * grain(p * 120.0)), brick);
        s.height = brick;
    }
#elif PATTERN_ID == PATTERN_CONCRETE
    {
        float f = fbm(p * scale);
        float speck = step(0.93, grain(p * 300.0));
        s.albedo = mix(accent, base, f) * (1.0 - 0.2 * speck);
        s.height = 0.3 * f + 0.2 * grain(p * 200.0);
    }
#elif PATTERN_ID == PATTERN_PLASTER
    {
        s.albedo = base * (1.0 + (fbm(p * scale) - 0.5) * variation * 2.0);
        s.height = 0.4 * grain(p * 300.0) + 0.6 * vnoise(p * 14.0);
    }
#elif PATTERN_ID == PATTERN_METAL
    {
        // Brushed streaks: smooth value noise stretched along the brushing, a faint relief (a hashed
        // cell per streak tilted the normal at every cell edge, and reflections broke into stripes).
        float brushed = vnoise(vec3(uv.x * 3.0, uv.y * scale, 0.0));
        s.albedo = base * (0.94 + 0.12 * brushed);
        s.roughness = rough * (0.85 + 0.3 * brushed);
        s.height = brushed * 0.05;
    }
#elif PATTERN_ID == PATTERN_TEXTURED
    {
        // A library model's texture (sRGB), tiling as its UVs say; its detail doubles as relief.
        vec3 texel = texture(u_library, vec3(v_uv, layer)).rgb;
        s.albedo = base * pow(texel, vec3(2.2));
        s.height = luminance(texel);
    }
#elif PATTERN_ID == PATTERN_FOLIAGE
    {
        float f = fbm(p * scale);
        s.albedo = mix(accent, base, f) * (0.8 + 0.4 * grain(p * scale * 3.0));
        s.height = f;
    }
#else
    {
        float f = fbm(p * scale);
        s.albedo = base * (1.0 + (f - 0.5) * variation);
        s.height = f * 0.2;
    }
#endif
    return s;
}

// Normal detail from a height field without tangents (Mikkelsen's surface gradient).
vec3 bumped(vec3 n, vec3 p, float height, float strength) {
    vec3 dpdx = dFdx(p), dpdy = dFdy(p);
    float dhdx = dFdx(height), dhdy = dFdy(height);
    vec3 r1 = cross(dpdy, n), r2 = cross(n, dpdx);
    float det = dot(dpdx, r1);
    if (abs(det) < 1e-12) return n;
    vec3 grad = (dhdx * r1 + dhdy * r2) / det;
    return normalize(n - strength * 0.01 * grad);
}

float ggx(float n_h, float a) {
    float a2 = a * a;
    float d = n_h * n_h * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

vec3 brdf(vec3 n, vec3 v, vec3 l, vec3 albedo, float roughness, float metalness) {
    vec3 h = normalize(v + l);
    float n_v = max(dot(n, v), 1e-3), n_l = max(dot(n, l), 1e-3), n_h = max(dot(n, h), 0.0);
    float a = max(roughness * roughness, 2e-3);
    float k = a * 0.5;
    float visibility = 0.25 / ((n_v * (1.0 - k) + k) * (n_l * (1.0 - k) + k));
    vec3 f0 = mix(vec3(0.04), albedo, metalness);
    vec3 fresnel = f0 + (1.0 - f0) * pow(clamp(1.0 - dot(v, h), 0.0, 1.0), 5.0);
    vec3 diffuse = (1.0 - fresnel) * (1.0 - metalness) * albedo / PI;
    return diffuse + ggx(n_h, a) * visibility * fresnel;
}

float sun_shadow(vec3 p, vec3 n) {
    vec4 c = u_sun_matrix * vec4(p + n * 0.015, 1.0);
    vec3 s = c.xyz / c.w;
    if (any(lessThan(s.xy, vec2(0.0))) || any(greaterThan(s.xy, vec2(1.0)))) return 1.0;
    vec2 texel = 1.0 / vec2(textureSize(u_sun_shadow, 0));
    float lit = 0.0;
    lit += texture(u_sun_shadow, vec3(s.xy + vec2(-1.2, -0.4) * texel, s.z - 0.0008));
    lit += texture(u_sun_shadow, vec3(s.xy + vec2(0.4, -1.2) * texel, s.z - 0.0008));
    lit += texture(u_sun_shadow, vec3(s.xy + vec2(1.2, 0.4) * texel, s.z - 0.0008));
    lit += texture(u_sun_shadow, vec3(s.xy + vec2(-0.4, 1.2) * texel, s.z - 0.0008));
    return lit * 0.25;
}

// Texel (in atlas texels) of direction d on cube row ``row``: the six 90 degree faces along +x, -x,
// +y, -y, +z, -z with the up vectors of GLRenderer.FACE_AXES, their projections written out (no
// dynamically indexed matrices, which are slow here). Lamp shadows and room probes share it.
vec2 cube_texel(vec3 d, float row, float tile) {
    vec3 a = abs(d);
    float face;
    vec2 ndc;
    if (a.x >= a.y && a.x >= a.z) {
        face = d.x > 0.0 ? 0.0 : 1.0;
        ndc = vec2(d.x > 0.0 ? -d.y : d.y, d.z) / a.x;
    } else if (a.y >= a.z) {
        face = d.y > 0.0 ? 2.0 : 3.0;
        ndc = vec2(d.y > 0.0 ? d.x : -d.x, d.z) / a.y;
    } else {
        face = d.z > 0.0 ? 4.0 : 5.0;
        ndc = vec2(d.z > 0.0 ? -d.x : d.x, d.y) / a.z;
    }
    vec2 uv = clamp(ndc * 0.5 + 0.5, 1.5 / tile, 1.0 - 1.5 / tile);
    return (vec2(face, row) + uv) * tile;
}

float lamp_shadow(float row, vec3 d) {
    vec2 texel = cube_texel(d, row, u_tile);
    float reach = length(d) - 0.01 - 0.005 * length(d);
    return texture(u_point_shadow, vec3(texel / u_atlas_texels, reach / LAMP_SHADOW_RANGE));
}

// What a mirror-like surface at p reflects along r: the room's probe (a cube map rendered from the
// room's middle), looked up where r leaves the room's box so the reflection stands where the room is.
vec3 room_reflection(int room, vec3 p, vec3 r) {
    vec3 lo = texelFetch(u_probe_boxes, ivec2(room, 0), 0).xyz;
    vec3 hi = texelFetch(u_probe_boxes, ivec2(room, 1), 0).xyz;
    vec3 centre = texelFetch(u_probe_boxes, ivec2(room, 2), 0).xyz;
    vec3 safe = sign(r) * max(abs(r), vec3(1e-4)) + vec3(equal(r, vec3(0.0))) * 1e-4;
    vec3 far_t = max((hi - p) / safe, (lo - p) / safe);
    float t = max(min(min(far_t.x, far_t.y), far_t.z), 0.0);
    vec2 texel = cube_texel(p + r * t - centre, float(room), u_probe_tile);
    return texture(u_probes, texel / u_probe_texels).rgb;
}

void main() {
    vec4 m0 = texelFetch(u_materials, ivec2(0, v_material), 0);
    vec4 m1 = texelFetch(u_materials, ivec2(1, v_material), 0);
    vec4 m2 = texelFetch(u_materials, ivec2(2, v_material), 0);
    float layer = texelFetch(u_materials, ivec2(3, v_material), 0).r;
    vec4 instance_room = texelFetch(u_instances, ivec2(v_instance, 0), 0);
    vec4 emission_kind = texelFetch(u_instances, ivec2(v_instance, 1), 0);
    vec4 levels = texelFetch(u_instances, ivec2(v_instance, 2), 0);
    int kind = int(emission_kind.a + 0.5);

    vec3 v = normalize(u_eye - v_world);
    vec3 n = normalize(v_normal);
    if (dot(n, v) < 0.0) n = -n;                       // thin parts are seen from both sides
    vec3 geometric = n;                                // before normal detail: for shadow offsets
    // The room this surface faces (a wall's far side, a door leaf seen from the next room belong
    // to the room in front of them), for its ambient light and for which lamps reach it.
    int room = int(texture(u_room_map, (v_world.xy + geometric.xy * 0.12 - u_room_box.xy) * u_room_box.zw).r + 0.5) - 1;
    if (room < 0) room = int(instance_room.a + 0.5);
    vec4 room_light = texelFetch(u_room_light, ivec2(room, 0), 0);   // rgb: bounce light, a: its windows
    vec3 ambient = room_light.rgb;
    vec3 seeded = v_local + (kind >= KIND_OBJECT ? hash12(vec2(float(v_instance), 1.0)) * 37.0 : 0.0);
    Surface s = pattern(m0.rgb, m2.rgb, m1.x, m1.y, m1.z, m1.w, seeded, layer);
    n = bumped(n, v_world, s.height, m2.a);

    vec3 colour;
#if PATTERN_ID == PATTERN_GLASS
    {
        // Window glass: the outdoors through it, the room faintly reflected.
        vec3 through = outdoor_at(v_world, -v);
        float fresnel = 0.04 + 0.96 * pow(clamp(1.0 - dot(n, v), 0.0, 1.0), 5.0);
        colour = mix(through * vec3(0.92, 0.96, 0.95), ambient * 0.5, fresnel);
    }
#else
    {
        float above_floor = v_world.z - levels.x;
        float occlusion = 1.0;
        vec2 cover_uv = (v_world.xy - u_coverage_box.xy) * u_coverage_box.zw;
        float cover = texture(u_coverage, cover_uv).r;
        if (kind == KIND_FLOOR) {
            occlusion = 1.0 - 0.6 * cover;
        } else if (kind == KIND_WALLS) {
            occlusion = (1.0 - 0.3 * exp(-above_floor / 0.2)) * (1.0 - 0.25 * exp(-(levels.y - v_world.z) / 0.25));
        } else if (kind != KIND_CEILING) {
            occlusion = mix(0.55, 1.0, smoothstep(0.0, 0.45, above_floor)) * (1.0 - 0.3 * cover * exp(-above_floor / 0.3));
        }
        vec3 diffuse_albedo = s.albedo * (1.0 - s.metalness);
        vec3 f0 = mix(vec3(0.04), s.albedo, s.metalness);
        // Sky and bounce light of the room; glossy and metal surfaces reflect a bright-above,
        // dark-below surround of the same colour.
        vec3 r = reflect(-v, n);
        float surround = mix(0.35, 1.4, clamp(r.z * 0.5 + 0.5, 0.0, 1.0));
        // Schlick's Fresnel: two unit vectors can have a dot product a rounding above 1, and
        // pow of a negative base is NaN on llvmpipe (one such pixel blacked out whole frames).
        vec3 env_f = f0 + (1.0 - f0) * pow(clamp(1.0 - dot(n, v), 0.0, 1.0), 5.0) * (1.0 - s.roughness);
        vec3 environment = ambient * surround;
#if GLOSSY
        if (u_probes_ready == 1) {
            environment = mix(room_reflection(room, v_world, r), environment, s.roughness);
        }
#endif
        colour = ambient * occlusion * diffuse_albedo + env_f * environment * (1.0 - 0.7 * s.roughness) * occlusion;
        colour += window_light(v_world + geometric * 0.02, n, room_light.a) * diffuse_albedo * (occlusion / PI);
#if PATTERN_ID == PATTERN_MIRROR
        colour = environment * vec3(0.86, 0.9, 0.9);
#endif
        // The sun.
        float n_l = dot(n, u_sun_dir);
        if (n_l > 0.0 && dot(u_sun_irradiance, vec3(1.0)) > 1e-4) {
            float lit = u_shadows == 1 ? sun_shadow(v_world, geometric) : 1.0;
            colour += brdf(n, v, u_sun_dir, s.albedo, s.roughness, s.metalness) * u_sun_irradiance * n_l * lit;
        }
        // Lamps and ceiling lights reaching this room, branch-free inside (a CPU rasteriser pays for
        // divergent branches, but a loop ends once no pixel of a block has lights left):
        // Lambert plus a normalised Blinn-Phong lobe matched to the roughness.
        float shininess = 2.0 / max(s.roughness * s.roughness * s.roughness * s.roughness, 1e-3);
        float lobe = (shininess + 8.0) / (8.0 * PI);
        vec3 lamp_diffuse = diffuse_albedo / PI;
        int lights = u_room_lights[room];
        for (int k = 0; k < (lights & 15); ++k) {
            int i = (lights >> (4 + 3 * k)) & 7;
            vec3 d = v_world - u_light_position[i].xyz;
            float dist2 = dot(d, d);
            float range2 = u_light_position[i].w * u_light_position[i].w;
            vec3 l = -d * inversesqrt(dist2);
            float n_l_lamp = max(dot(n, l), 0.0);
            float window = clamp(1.0 - dist2 * dist2 / (range2 * range2), 0.0, 1.0);
            float row = u_light_power[i].w;
            float lit = (row >= 0.0 && n_l_lamp > 0.0) ? lamp_shadow(row, d + geometric * 0.02) : 1.0;
            float n_h = max(dot(n, normalize(v + l)), 0.0);
            vec3 irradiance = u_light_power[i].rgb * (window * window * lit * n_l_lamp / (dist2 + 0.04));
            colour += irradiance * (lamp_diffuse + f0 * lobe * pow(n_h, shininess));
        }
#if PATTERN_ID == PATTERN_EMISSIVE
        colour += emission_kind.rgb * s.albedo;
#endif
    }
#endif
    out_hdr = vec4(colour, log(luminance(colour) + 1e-4));
    out_depth = v_eye_z;
    out_instance = v_instance;
}
