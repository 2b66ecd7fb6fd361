/// \file shader_sources.hpp
/// GLSL sources from shaders/*.glsl, embedded at build time
/// (caliper_embed_files in cmake/CaliperOptions.cmake).
#pragma once

namespace caliper::render::shaders {
extern const char* const kMeshVert;
extern const char* const kMeshFrag;
extern const char* const kFlatVert;
extern const char* const kFlatFrag;
extern const char* const kOverlayVert;
extern const char* const kOverlayFrag;
extern const char* const kImguiVert;  ///< Dear ImGui draw lists (the editor)
extern const char* const kImguiFrag;
}  // namespace caliper::render::shaders
