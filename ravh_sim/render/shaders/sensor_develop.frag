// The sensor's signal made an image: white balance (gains chosen by the sensor model from
// sensor_balance.frag's means), the renderer's ACES curve and sRGB encoding.
uniform sampler2D u_signal;
uniform vec3 u_balance;
uniform float u_output_gain;        // full scale to the curve's input (SensorModel.output_gain)
out vec4 out_colour;

void main() {
    vec4 signal = texelFetch(u_signal, ivec2(gl_FragCoord.xy), 0);
    out_colour = vec4(srgb_encode(aces(min(signal.rgb * u_balance, 1.0) * u_output_gain)), 1.0);
}
