// Grey-world statistics of the sensor's signal: each output texel is the mean of a block of pixels
// per channel (alpha: how many), so white balance reads a few hundred texels instead of the frame.
uniform sampler2D u_signal;
uniform int u_block;
out vec4 out_means;
void main() {
    ivec2 origin = ivec2(gl_FragCoord.xy) * u_block;
    ivec2 size = textureSize(u_signal, 0);
    ivec2 end = min(origin + u_block, size);
    vec3 sum = vec3(0.0);
    for (int y = origin.y; y < end.y; ++y) {
        for (int x = origin.x; x < end.x; ++x) {
            sum += texelFetch(u_signal, ivec2(x, y), 0).rgb;
        }
    }
    float count = float((end.x - origin.x) * (end.y - origin.y));
    out_means = vec4(sum / max(count, 1.0), count);
}
