// Included first by every kernel: GLSL version, extensions and the workgroup-is-one-subgroup layout.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require

// Kernels built on subgroup operations run one subgroup per workgroup. The host sets this to the device's
// subgroup size and pins it (full subgroups of exactly this size), so never assume 32 here.
layout(constant_id = 0) const uint SUBGROUP_SIZE = 32;
layout(local_size_x_id = 0) in;
