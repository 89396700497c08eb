// The preview images `dispex extract --preview DIR` writes beside a map.
#include <filesystem>
#include <system_error>

#include "dispex/render.h"

namespace dispex {

Status WritePreviews(const std::string& base_path, const std::string& map_path,
                     const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    return Status::Error(dir + ": cannot create the preview folder" +
                         (ec ? ": " + ec.message() : std::string()));
  }
  DISPEX_ASSIGN_OR_RETURN(Mesh base, ReadMesh(base_path));
  DISPEX_ASSIGN_OR_RETURN(PtexFile map, PtexFile::Open(map_path));
  const std::string stem = fs::path(map_path).stem().string();

  AtlasOptions atlas_options;
  atlas_options.mode = DefaultAtlasMode(map);
  DISPEX_ASSIGN_OR_RETURN(Image atlas, RenderAtlas(map, atlas_options));
  DISPEX_RETURN_IF_ERROR(WritePng((fs::path(dir) / (stem + "_atlas.png")).string(), atlas));

  SurfaceRenderOptions options;
  options.width = 960;
  options.height = 360;
  DISPEX_ASSIGN_OR_RETURN(Image compare, RenderComparison(base, map, nullptr, options));
  return WritePng((fs::path(dir) / (stem + "_compare.png")).string(), compare);
}

}  // namespace dispex
