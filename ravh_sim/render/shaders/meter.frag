// Exposure metering: each output texel averages, over a block of pixels, the log luminance (HDR
// alpha) sampling every second pixel in each direction (the renderer's own auto-exposure), and the
// linear luminance of every pixel (what a sensor model meters). Non-finite values are left out of
// both (a shader fault must not decide the exposure of the whole frame), and the count of finite
// pixels tells the renderer to refuse a frame that has any.
uniform sampler2D u_hdr;
uniform int u_block;
out vec4 out_meter;          // mean log luminance, its samples, mean linear luminance, its samples
void main() {
    ivec2 origin = ivec2(gl_FragCoord.xy) * u_block;
    ivec2 size = textureSize(u_hdr, 0);
    float sum = 0.0, count = 0.0, linear = 0.0, pixels = 0.0;
    for (int y = 0; y < u_block; ++y) {
        for (int x = 0; x < u_block; ++x) {
            ivec2 at = origin + ivec2(x, y);
            vec4 value = texelFetch(u_hdr, min(at, size - 1), 0);
            bool inside = at.x < size.x && at.y < size.y;
            bool sampled = inside && (x % 2 == 0) && (y % 2 == 0) && !isnan(value.a) && !isinf(value.a);
            sum += sampled ? value.a : 0.0;
            count += sampled ? 1.0 : 0.0;
            float l = luminance(value.rgb);
            bool finite = inside && !isnan(l) && !isinf(l);
            linear += finite ? l : 0.0;
            pixels += finite ? 1.0 : 0.0;
        }
    }
    out_meter = vec4(sum / max(count, 1.0), count, linear / max(pixels, 1.0), pixels);
}
