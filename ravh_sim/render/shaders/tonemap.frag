// Camera response of the renderer's own (ideal) camera: the exposure metered from the frame, the ACES
// filmic curve and sRGB encoding. Non-finite radiance never gets here: the meter counts it and the
// renderer refuses the frame.
uniform sampler2D u_hdr;
uniform float u_exposure;
out vec4 out_colour;

void main() {
    out_colour = vec4(srgb_encode(aces(texelFetch(u_hdr, ivec2(gl_FragCoord.xy), 0).rgb * u_exposure)), 1.0);
}
