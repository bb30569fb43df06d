// Shadow casters: the sun's orthographic map (u_origin = 0) or one cube face of a lamp (u_origin =
// the lamp, the fragment's depth is the distance to it). Window glass casts no shadow.
uniform mat4 u_matrix;
uniform vec3 u_origin;
in vec3 in_position;
in float in_material;
out vec3 v_offset;
flat out int v_material;
void main() {
    v_offset = in_position - u_origin;
    v_material = int(in_material + 0.5);
    gl_Position = u_matrix * vec4(v_offset, 1.0);
}
