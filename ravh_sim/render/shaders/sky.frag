uniform mat4 u_inverse_view_proj;
in vec2 v_ndc;
layout(location = 0) out vec4 out_hdr;
layout(location = 1) out float out_depth;
layout(location = 2) out int out_instance;

void main() {
    vec4 far_point = u_inverse_view_proj * vec4(v_ndc, 1.0, 1.0);
    vec4 near_point = u_inverse_view_proj * vec4(v_ndc, -1.0, 1.0);
    vec3 d = normalize(far_point.xyz / far_point.w - near_point.xyz / near_point.w);
    vec3 c = outdoor_at(near_point.xyz / near_point.w, d);
    out_hdr = vec4(c, log(luminance(c) + 1e-4));
    out_depth = 0.0;
    out_instance = 0;
}
