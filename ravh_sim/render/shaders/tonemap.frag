// Camera response: the exposure (metered from the frame), ACES filmic curve, sRGB encoding.
uniform sampler2D u_hdr;
uniform float u_exposure;
out vec4 out_colour;

vec3 aces(vec3 x) {
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

void main() {
    vec3 c = aces(texelFetch(u_hdr, ivec2(gl_FragCoord.xy), 0).rgb * u_exposure);
    vec3 srgb = mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
    out_colour = vec4(srgb, 1.0);
}
