uniform mat4 u_view_proj;
uniform mat4 u_view;
in vec3 in_position;
in vec3 in_normal;
in vec3 in_local;
in float in_material;
in float in_instance;
in vec2 in_uv;
out vec3 v_world;
out vec3 v_normal;
out vec3 v_local;
out float v_eye_z;
out vec2 v_uv;
flat out int v_material;
flat out int v_instance;
invariant gl_Position;                 // the depth pre-pass and the shading pass must agree exactly

void main() {
    v_world = in_position;
    v_normal = in_normal;
    v_local = in_local;
    v_uv = in_uv;
    v_material = int(in_material + 0.5);
    v_instance = int(in_instance + 0.5);
    v_eye_z = -(u_view * vec4(in_position, 1.0)).z;
    gl_Position = u_view_proj * vec4(in_position, 1.0);
}
