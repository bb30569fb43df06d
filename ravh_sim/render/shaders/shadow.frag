uniform sampler2D u_materials;
in vec3 v_offset;
flat in int v_material;
out float out_distance;
void main() {
    if (int(texelFetch(u_materials, ivec2(0, v_material), 0).a + 0.5) == PATTERN_GLASS) discard;
    out_distance = length(v_offset);
}
