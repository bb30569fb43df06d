// Shadow casters' depth: the sun's orthographic depth, or (u_radial, a lamp's cube face) the distance
// to the lamp over LAMP_SHADOW_RANGE, so one depth-compared look-up tells whether a point is the
// nearest to the lamp along its ray. Window glass casts no shadow.
uniform sampler2D u_materials;
uniform int u_radial;
in vec3 v_offset;
flat in int v_material;
void main() {
    if (int(texelFetch(u_materials, ivec2(0, v_material), 0).a + 0.5) == PATTERN_GLASS) discard;
    gl_FragDepth = u_radial == 1 ? length(v_offset) / LAMP_SHADOW_RANGE : gl_FragCoord.z;
}
