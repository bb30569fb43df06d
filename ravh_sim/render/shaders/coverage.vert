uniform mat4 u_matrix;
in vec3 in_position;
in float in_instance;
out vec3 v_offset;
flat out int v_instance_id;
void main() {
    v_offset = in_position;
    v_instance_id = int(in_instance + 0.5);
    gl_Position = u_matrix * vec4(in_position, 1.0);
}
