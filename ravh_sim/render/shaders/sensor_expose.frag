// The camera sensor, per pixel (ravh_sim.sensors.imaging.SensorModel.expose is the reference; the
// sensor model decides exposure, blur and balance, this pass only carries them out): the radiance
// swept over the exposure by the robot's motion, the electrons it frees with photon shot noise and
// read noise, clipped at the full well, amplified by the gain and quantised by the ADC. Writes the
// signal in full-scale units (non-finite radiance never gets here: the renderer refuses the frame).
uniform sampler2D u_hdr;            // linear filtering: the sweep samples between pixels
uniform float u_electrons;          // e- per unit radiance: sensitivity x exposure time
uniform float u_read_noise;         // e- rms
uniform float u_full_well;          // e-
uniform float u_gain;
uniform float u_levels;             // the ADC's largest code
uniform vec2 u_principal;           // cx, cy in image pixels (y down)
uniform float u_shift;              // px the exposure's turn sweeps the image sideways
uniform float u_zoom;               // how much the exposure's drive zooms it
uniform int u_samples;              // copies along the sweep (1: no blur)
uniform uvec2 u_seed;               // this frame's noise stream
out vec4 out_signal;

// Counter-based random numbers: one pcg4d hash per call (Jarzynski & Olano, JCGT 2020), so each
// pixel's noise depends only on its place and the frame's seed.
uvec4 pcg4d(uvec4 v) {
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
    v ^= v >> 16u;
    v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
    return v;
}

vec4 uniform01(uvec4 bits) {          // in (0, 1): never 0, so logs stay finite
    return (vec4(bits >> 8u) + 0.5) / 16777216.0;
}

// Shot noise (Poisson) plus read noise (Gaussian) on a mean of ``mean`` electrons. Few electrons:
// the Poisson count by inversion of its distribution; many: the sum is Gaussian with the summed
// variance (the skew this leaves out is at most 0.13, at 12 electrons and 3 e- of read noise).
float electrons(float mean, float u, float normal) {
    if (mean < 12.0) {
        float p = exp(-mean), cumulative = p, k = 0.0;
        for (int i = 0; i < 48 && u > cumulative; ++i) {
            k += 1.0;
            p *= mean / k;
            cumulative += p;
        }
        return k + u_read_noise * normal;
    }
    return mean + sqrt(mean + u_read_noise * u_read_noise) * normal;
}

vec3 swept_radiance(ivec2 pixel, ivec2 size) {
    if (u_samples < 2) return texelFetch(u_hdr, pixel, 0).rgb;
    vec2 image = vec2(pixel.x, size.y - 1 - pixel.y);            // image pixel, y down
    vec3 sum = vec3(0.0);
    for (int i = 0; i < u_samples; ++i) {
        float t = float(i) / float(u_samples - 1) - 0.5;
        float scale = 1.0 + u_zoom * t;
        vec2 source = (image - (1.0 - scale) * u_principal - vec2(u_shift * t, 0.0)) / scale;
        vec2 gl = vec2(source.x + 0.5, float(size.y) - 0.5 - source.y) / vec2(size);
        sum += texture(u_hdr, gl).rgb;
    }
    return sum / float(u_samples);
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec3 radiance = swept_radiance(pixel, textureSize(u_hdr, 0));
    vec3 mean = max(radiance, 0.0) * u_electrons;
    vec4 a = uniform01(pcg4d(uvec4(pixel, u_seed)));
    vec4 b = uniform01(pcg4d(uvec4(pixel, u_seed ^ uvec2(0x9e3779b9u, 0x85ebca6bu))));
    float r1 = sqrt(-2.0 * log(b.x)), r2 = sqrt(-2.0 * log(b.z));          // Box-Muller: normals from b
    vec3 normal = vec3(r1 * cos(2.0 * PI * b.y), r1 * sin(2.0 * PI * b.y), r2 * cos(2.0 * PI * b.w));
    vec3 charge = vec3(electrons(mean.r, a.x, normal.x), electrons(mean.g, a.y, normal.y),
                       electrons(mean.b, a.z, normal.z));
    vec3 signal = clamp(clamp(charge, 0.0, u_full_well) * (u_gain / u_full_well), 0.0, 1.0);
    out_signal = vec4(round(signal * u_levels) / u_levels, 1.0);
}
