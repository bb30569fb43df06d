// Top-down coverage of walls and furniture near the floor: blurred, it darkens floors under and
// beside things (ambient occlusion) without a per-frame cost.
uniform sampler2D u_instances;
in vec3 v_offset;
flat in int v_instance_id;
out float out_cover;
void main() {
    vec4 kind = texelFetch(u_instances, ivec2(v_instance_id, 1), 0);
    float floor_z = texelFetch(u_instances, ivec2(v_instance_id, 2), 0).x;
    int k = int(kind.a + 0.5);
    if (k == KIND_FLOOR || k == KIND_CEILING || v_offset.z - floor_z > 1.0) discard;
    out_cover = 1.0;
}
