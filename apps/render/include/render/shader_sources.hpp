/// \file shader_sources.hpp
/// GLSL sources from shaders/*.glsl, embedded at build time
/// (caliper_embed_files in cmake/CaliperOptions.cmake).
#pragma once

namespace caliper::render::shaders {
extern const char* const kMeshVert;
extern const char* const kMeshFrag;
extern const char* const kFlatVert;  ///< needs kUnlitVertex; also the editor's ImGui draw lists
extern const char* const kFlatFrag;
extern const char* const kOverlayVert;  ///< needs kUnlitVertex
extern const char* const kOverlayFrag;
/// The vertex layout of the flat and overlay programs: link_program()'s `vertex_prelude` for
/// kFlatVert and kOverlayVert.
extern const char* const kUnlitVertex;
}  // namespace caliper::render::shaders
