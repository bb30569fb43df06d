// Exposure metering: each output texel averages the log luminance (HDR alpha) of a block of pixels.
uniform sampler2D u_hdr;
uniform int u_block;
out float out_log_luminance;
void main() {
    ivec2 origin = ivec2(gl_FragCoord.xy) * u_block;
    ivec2 size = textureSize(u_hdr, 0);
    float sum = 0.0;
    int count = 0;
    for (int y = 0; y < u_block; y += 2) {
        for (int x = 0; x < u_block; x += 2) {
            ivec2 at = origin + ivec2(x, y);
            if (at.x < size.x && at.y < size.y) {
                sum += texelFetch(u_hdr, at, 0).a;
                count += 1;
            }
        }
    }
    out_log_luminance = sum / float(max(count, 1));
}
