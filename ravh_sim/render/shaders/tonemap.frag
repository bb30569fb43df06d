// Camera response: the exposure (metered from the frame), ACES filmic curve, sRGB encoding. Alpha
// flags pixels whose radiance is not a finite number (0), so a shader fault is never stored silently.
uniform sampler2D u_hdr;
uniform float u_exposure;
out vec4 out_colour;

vec3 aces(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

void main() {
    vec3 hdr = texelFetch(u_hdr, ivec2(gl_FragCoord.xy), 0).rgb;
    bool finite = !any(isnan(hdr)) && !any(isinf(hdr));
    vec3 c = aces((finite ? hdr : vec3(0.0)) * u_exposure);
    vec3 srgb = mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
    out_colour = vec4(srgb, finite ? 1.0 : 0.0);
}
