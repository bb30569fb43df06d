// Exposure metering: each output texel averages the log luminance (HDR alpha) of a block of pixels,
// sampling every second pixel in each direction. Non-finite values are left out of the average (a
// shader fault must not decide the exposure of the whole frame; tonemap.frag flags those pixels).
uniform sampler2D u_hdr;
uniform int u_block;
out vec2 out_log_luminance;          // mean log luminance, number of samples in it
void main() {
    ivec2 origin = ivec2(gl_FragCoord.xy) * u_block;
    ivec2 size = textureSize(u_hdr, 0);
    float sum = 0.0;
    float count = 0.0;
    for (int y = 0; y < u_block; y += 2) {
        for (int x = 0; x < u_block; x += 2) {
            ivec2 at = origin + ivec2(x, y);
            float value = texelFetch(u_hdr, min(at, size - 1), 0).a;
            bool use = at.x < size.x && at.y < size.y && !isnan(value) && !isinf(value);
            sum += use ? value : 0.0;
            count += use ? 1.0 : 0.0;
        }
    }
    out_log_luminance = vec2(sum / max(count, 1.0), count);
}
