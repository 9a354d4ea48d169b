#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_EXT_shader_atomic_float : require
// Backward of the per-pixel pass; see rasterize_backward.glsl.
#define SPLAT_BWD_MODE SPLAT_BWD_FLOAT_ATOMICS
#include "splat/rasterize_backward.glsl"
