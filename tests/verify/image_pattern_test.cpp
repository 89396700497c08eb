// The image pattern (Pattern::kImage): PNG decoding and luminance against images written by
// libpng's own simplified writer, bilinear wrapping lookups, the cage's UV charts against
// OpenSubdiv's Bfr evaluating the same UVs as a linear face-varying surface, and truth files
// whose h is known in closed form (an RGB ramp image), plus the errors a user can cause.
#include <gtest/gtest.h>
#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <png.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "../extract/e2e_support.h"
#include "core/png_io.h"
#include "dispex/mesh.h"
#include "dispex/subdiv.h"
#include "dispex/uv_charts.h"
#include "dispex/verify.h"
#include "verify/height_image.h"

namespace dispex {
namespace {

using namespace verify;
using testing::DataPath;
using testing::TempDir;

// ---- PNG files written by libpng's simplified API (an independent writer) ------------------

// `pixels`: rows from the top, 8-bit samples, or 16-bit host-order samples for the LINEAR
// formats (which libpng writes as 16-bit PNGs with the values unchanged).
std::vector<std::uint8_t> EncodeWithLibpng(int width, int height, png_uint_32 format,
                                           const void* pixels, const void* colormap = nullptr,
                                           int colormap_entries = 0) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = format;
  image.colormap_entries = static_cast<png_uint_32>(colormap_entries);
  png_alloc_size_t size = 0;
  EXPECT_TRUE(png_image_write_to_memory(&image, nullptr, &size, 0, pixels, 0, colormap))
      << image.message;
  std::vector<std::uint8_t> bytes(size);
  EXPECT_TRUE(png_image_write_to_memory(&image, bytes.data(), &size, 0, pixels, 0, colormap))
      << image.message;
  bytes.resize(size);
  return bytes;
}

void WriteFile(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
}

HeightImage Decode(const std::vector<std::uint8_t>& bytes) {
  auto pixels = DecodePngPixels(bytes.data(), bytes.size(), "t.png", PngConversion::kNative);
  EXPECT_TRUE(pixels.ok()) << pixels.status().message();
  return pixels.ok() ? HeightImage::FromPixels(*pixels) : HeightImage{};
}

double Rec709(double r, double g, double b) {
  return 0.2126 * r + 0.7152 * g + 0.0722 * b;
}

TEST(HeightImage, LuminanceOfEveryColourTypeWithRowZeroAtTheBottom) {
  // 3 x 2 pixels; PNG row 0 is the top, so HeightImage row 0 is PNG row 1.
  const std::uint8_t grey[] = {0, 51, 255, 7, 128, 200};
  HeightImage g = Decode(EncodeWithLibpng(3, 2, PNG_FORMAT_GRAY, grey));
  ASSERT_EQ(g.width(), 3);
  ASSERT_EQ(g.height(), 2);
  for (int i = 0; i < 3; ++i) {
    EXPECT_FLOAT_EQ(g.at(i, 1), grey[i] / 255.0f);
    EXPECT_FLOAT_EQ(g.at(i, 0), grey[3 + i] / 255.0f);
  }

  const std::uint16_t grey16[] = {0, 1, 65535, 32768, 12345, 65534};
  HeightImage g16 = Decode(EncodeWithLibpng(3, 2, PNG_FORMAT_LINEAR_Y, grey16));
  for (int i = 0; i < 3; ++i) {
    EXPECT_FLOAT_EQ(g16.at(i, 1), static_cast<float>(grey16[i] / 65535.0));
    EXPECT_FLOAT_EQ(g16.at(i, 0), static_cast<float>(grey16[3 + i] / 65535.0));
  }

  const std::uint8_t ga[] = {10, 255, 20, 0, 30, 128, 40, 255, 50, 1, 60, 255};  // alpha ignored
  HeightImage a = Decode(EncodeWithLibpng(3, 2, PNG_FORMAT_GA, ga));
  EXPECT_FLOAT_EQ(a.at(1, 1), 20 / 255.0f);
  EXPECT_FLOAT_EQ(a.at(2, 0), 60 / 255.0f);

  const std::uint8_t rgb[] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 10, 20, 30, 255, 255, 255, 0, 0, 0};
  HeightImage c = Decode(EncodeWithLibpng(3, 2, PNG_FORMAT_RGB, rgb));
  EXPECT_NEAR(c.at(0, 1), 0.2126, 1e-7);
  EXPECT_NEAR(c.at(1, 1), 0.7152, 1e-7);
  EXPECT_NEAR(c.at(2, 1), 0.0722, 1e-7);
  EXPECT_NEAR(c.at(0, 0), Rec709(10, 20, 30) / 255, 1e-7);
  EXPECT_NEAR(c.at(1, 0), 1.0, 1e-7);
  EXPECT_NEAR(c.at(2, 0), 0.0, 1e-7);

  const std::uint8_t rgba[] = {10, 20, 30, 0, 40, 50, 60, 255};
  HeightImage ca = Decode(EncodeWithLibpng(2, 1, PNG_FORMAT_RGBA, rgba));
  EXPECT_NEAR(ca.at(0, 0), Rec709(10, 20, 30) / 255, 1e-7);
  EXPECT_NEAR(ca.at(1, 0), Rec709(40, 50, 60) / 255, 1e-7);

  const std::uint16_t rgb16[] = {65535, 0, 0, 1000, 2000, 3000};
  HeightImage c16 = Decode(EncodeWithLibpng(2, 1, PNG_FORMAT_LINEAR_RGB, rgb16));
  EXPECT_NEAR(c16.at(0, 0), 0.2126, 1e-7);
  EXPECT_NEAR(c16.at(1, 0), Rec709(1000, 2000, 3000) / 65535, 1e-7);

  // A palette image: indices into an RGB colour map, expanded.
  const std::uint8_t colormap[] = {0, 0, 0, 200, 100, 50, 255, 255, 255};
  const std::uint8_t indices[] = {1, 0, 2, 1};
  HeightImage p = Decode(EncodeWithLibpng(2, 2, PNG_FORMAT_RGB_COLORMAP, indices, colormap, 3));
  EXPECT_NEAR(p.at(0, 1), Rec709(200, 100, 50) / 255, 1e-7);
  EXPECT_NEAR(p.at(1, 1), 0.0, 1e-7);
  EXPECT_NEAR(p.at(0, 0), 1.0, 1e-7);
}

TEST(HeightImage, BilinearBetweenPixelCentresWithWrapping) {
  // 4 x 2 grey: PNG top row 0, 40, 80, 120; bottom row 200, 160, 120, 80.
  const std::uint8_t grey[] = {0, 40, 80, 120, 200, 160, 120, 80};
  HeightImage image = Decode(EncodeWithLibpng(4, 2, PNG_FORMAT_GRAY, grey));
  auto L = [](double v) { return v / 255; };
  // Pixel centres: ((i + 0.5) / 4, (j + 0.5) / 2), j from the bottom.
  EXPECT_NEAR(image.Sample(0.125, 0.25), L(200), 1e-7);
  EXPECT_NEAR(image.Sample(0.375, 0.75), L(40), 1e-7);
  // Half-way between two centres in s, in t, and in both.
  EXPECT_NEAR(image.Sample(0.25, 0.25), L(180), 1e-7);
  EXPECT_NEAR(image.Sample(0.125, 0.5), L(100), 1e-7);
  EXPECT_NEAR(image.Sample(0.25, 0.5), L((200 + 160 + 0 + 40) / 4.0), 1e-7);
  // A quarter of the way from centre (1, 0) to centre (2, 0).
  EXPECT_NEAR(image.Sample(0.4375, 0.25), L(0.75 * 160 + 0.25 * 120), 1e-7);
  // Repeat: the image edges blend the last and first columns and rows.
  EXPECT_NEAR(image.Sample(0.0, 0.25), L((200 + 80) / 2.0), 1e-7);
  EXPECT_NEAR(image.Sample(1.0, 0.25), L((200 + 80) / 2.0), 1e-7);
  EXPECT_NEAR(image.Sample(0.125, 0.0), L((200 + 0) / 2.0), 1e-7);
  for (double s : {-2.3, -0.01, 0.3, 0.97}) {
    for (double t : {-1.2, 0.1, 0.6}) {
      EXPECT_NEAR(image.Sample(s + 1, t), image.Sample(s, t), 1e-7);
      EXPECT_NEAR(image.Sample(s, t - 3), image.Sample(s, t), 1e-7);
    }
  }
  // Far outside the unit square (still finite) stays in range.
  const double far = image.Sample(1e12 + 0.3, -1e15);
  EXPECT_GE(far, 0.0);
  EXPECT_LE(far, 1.0);
  // A single pixel is constant everywhere.
  const std::uint8_t one[] = {77};
  HeightImage single = Decode(EncodeWithLibpng(1, 1, PNG_FORMAT_GRAY, one));
  EXPECT_NEAR(single.Sample(0.9, 0.1), L(77), 1e-7);
}

// ---- Hostile and broken PNGs ---------------------------------------------------------------

void PutBigEndian32(std::uint32_t value, std::uint8_t* out) {
  out[0] = static_cast<std::uint8_t>(value >> 24);
  out[1] = static_cast<std::uint8_t>(value >> 16);
  out[2] = static_cast<std::uint8_t>(value >> 8);
  out[3] = static_cast<std::uint8_t>(value);
}

// A PNG chunk: length, type, data, CRC-32 of type and data (zlib's crc32).
std::vector<std::uint8_t> Chunk(const char type[5], const std::vector<std::uint8_t>& data) {
  std::vector<std::uint8_t> out(12 + data.size());
  PutBigEndian32(static_cast<std::uint32_t>(data.size()), out.data());
  std::memcpy(out.data() + 4, type, 4);
  if (!data.empty()) std::memcpy(out.data() + 8, data.data(), data.size());
  const uLong crc = crc32(0, out.data() + 4, static_cast<uInt>(4 + data.size()));
  PutBigEndian32(static_cast<std::uint32_t>(crc), out.data() + 8 + data.size());
  return out;
}

// A PNG whose header claims width x height 8-bit grey and whose only IDAT holds `idat`.
std::vector<std::uint8_t> ForgedPng(std::uint32_t width, std::uint32_t height,
                                    const std::vector<std::uint8_t>& idat) {
  std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<std::uint8_t> ihdr(13, 0);
  PutBigEndian32(width, ihdr.data());
  PutBigEndian32(height, ihdr.data() + 4);
  ihdr[8] = 8;  // bit depth; colour type 0 (grey), no interlace
  for (const auto& c : {Chunk("IHDR", ihdr), Chunk("IDAT", idat), Chunk("IEND", {})}) {
    png.insert(png.end(), c.begin(), c.end());
  }
  return png;
}

std::string DecodeError(const std::vector<std::uint8_t>& bytes) {
  auto pixels = DecodePngPixels(bytes.data(), bytes.size(), "bad.png", PngConversion::kNative);
  EXPECT_FALSE(pixels.ok());
  if (pixels.ok()) return {};
  const std::string& m = pixels.status().message();
  EXPECT_EQ(m.rfind("bad.png: ", 0), 0u) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  return m;
}

TEST(PngRead, HostileFilesGiveAStatus) {
  const std::uint8_t grey[64] = {1, 2, 3};
  const std::vector<std::uint8_t> good = EncodeWithLibpng(8, 8, PNG_FORMAT_GRAY, grey);
  ASSERT_TRUE(DecodePngPixels(good.data(), good.size(), "ok.png", PngConversion::kNative).ok());

  EXPECT_NE(DecodeError({'n', 'o', 't', ' ', 'a', ' ', 'p', 'n', 'g'}).find("bad signature"),
            std::string::npos);
  EXPECT_NE(DecodeError({}).find("bad signature"), std::string::npos);
  for (std::size_t keep : {std::size_t{8}, std::size_t{20}, good.size() / 2, good.size() - 13}) {
    DecodeError(std::vector<std::uint8_t>(good.begin(), good.begin() + keep));
  }
  std::vector<std::uint8_t> bad_crc = good;
  bad_crc[bad_crc.size() - 20] ^= 0x55;  // inside the IDAT chunk or its CRC
  DecodeError(bad_crc);

  // Sizes: over libpng's user limit (2^20 per side), over 2^28 pixels, and a size whose
  // scanlines no IDAT of a few bytes could inflate to -- refused before allocating.
  const std::vector<std::uint8_t> idat = {0x78, 0x9c, 0x63, 0x00, 0x00, 0x00, 0x01, 0x00, 0x01};
  EXPECT_NE(DecodeError(ForgedPng(1u << 21, 1, idat)).find("cannot read PNG"), std::string::npos);
  EXPECT_NE(DecodeError(ForgedPng(1u << 20, 1u << 20, idat)).find("2^28 pixels"),
            std::string::npos);
  EXPECT_NE(DecodeError(ForgedPng(16000, 16000, idat)).find("cannot fit in the file"),
            std::string::npos);
  EXPECT_NE(DecodeError(ForgedPng(0, 5, idat)).find("cannot read PNG"), std::string::npos);
  // A plausible size with too little data: libpng runs out of image data.
  DecodeError(ForgedPng(40, 40, idat));
}

// ---- UV charts against OpenSubdiv ----------------------------------------------------------

// The cage's UVs as a linear face-varying channel of a Far::TopologyRefiner built here from
// the raw arrays, evaluated by Bfr at normalized sub-face coordinates (the Ptex coordinates
// of Far::PtexIndices' sub-faces), one Ptex face after another in base-face order.
class BfrUvOracle {
 public:
  explicit BfrUvOracle(const Mesh& cage) : cage_(cage) {
    namespace Far = OpenSubdiv::Far;
    namespace Sdc = OpenSubdiv::Sdc;
    sizes_.resize(cage.num_faces());
    for (std::size_t f = 0; f < cage.num_faces(); ++f) sizes_[f] = cage.face_size(f);
    Far::TopologyDescriptor desc;
    desc.numVertices = static_cast<int>(cage.num_vertices());
    desc.numFaces = static_cast<int>(cage.num_faces());
    desc.numVertsPerFace = sizes_.data();
    desc.vertIndicesPerFace = cage.face_indices.data();
    Far::TopologyDescriptor::FVarChannel channel;
    channel.numValues = static_cast<int>(cage.num_uvs());
    channel.valueIndices = cage.face_uv_indices.data();
    desc.numFVarChannels = 1;
    desc.fvarChannels = &channel;
    Sdc::Options options;
    options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    options.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL);
    refiner_.reset(Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Create(
        desc, Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Options(Sdc::SCHEME_CATMARK,
                                                                            options)));
    if (refiner_) factory_ = std::make_unique<OpenSubdiv::Bfr::RefinerSurfaceFactory<>>(*refiner_);
    uvs_.assign(cage.uvs.begin(), cage.uvs.end());
  }

  bool ok() const { return factory_ != nullptr; }

  // Ptex faces in base-face order: one per quad, one per corner of any other face.
  int num_ptex_faces() const {
    int n = 0;
    for (int size : sizes_) n += size == 4 ? 1 : size;
    return n;
  }

  // The UV at (u, v) of Ptex face `ptex`. Faces are found by walking the base faces; the
  // Bfr surface of the last base face is kept.
  bool Evaluate(int ptex, double u, double v, double uv[2]) {
    using Surface = OpenSubdiv::Bfr::Surface<double>;
    int base = 0, first = 0;
    while (base < static_cast<int>(sizes_.size())) {
      const int count =
          sizes_[static_cast<std::size_t>(base)] == 4 ? 1 : sizes_[static_cast<std::size_t>(base)];
      if (ptex < first + count) break;
      first += count;
      ++base;
    }
    if (base == static_cast<int>(sizes_.size())) return false;
    if (base != bound_) {
      bound_ = -1;
      if (!factory_->InitFaceVaryingSurface(base, &surface_, 0) || !surface_.IsValid()) {
        return false;
      }
      patch_.resize(2 * static_cast<std::size_t>(surface_.GetNumPatchPoints()));
      surface_.PreparePatchPoints(uvs_.data(), Surface::PointDescriptor(2), patch_.data(),
                                  Surface::PointDescriptor(2));
      bound_ = base;
    }
    const auto param = surface_.GetParameterization();
    const double st[2] = {u, v};
    double coord[2] = {u, v};
    if (param.HasSubFaces()) param.ConvertNormalizedSubFaceToCoord(ptex - first, st, coord);
    surface_.Evaluate(coord, patch_.data(), Surface::PointDescriptor(2), uv);
    return true;
  }

 private:
  const Mesh& cage_;
  std::vector<int> sizes_;
  std::vector<double> uvs_;
  std::unique_ptr<OpenSubdiv::Far::TopologyRefiner> refiner_;
  std::unique_ptr<OpenSubdiv::Bfr::RefinerSurfaceFactory<>> factory_;
  OpenSubdiv::Bfr::Surface<double> surface_;
  std::vector<double> patch_;
  int bound_ = -1;
};

Mesh ReadCage(const std::string& relative) {
  auto mesh = ReadMesh(DataPath(relative));
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  return mesh.ok() ? std::move(mesh).value() : Mesh{};
}

class UvCharts : public ::testing::TestWithParam<const char*> {};

TEST_P(UvCharts, AgreeWithBfrLinearFaceVaryingInterpolation) {
  const Mesh cage = ReadCage(GetParam());
  ASSERT_TRUE(cage.has_uvs());
  auto surface = LimitSurface::Build(cage);
  ASSERT_TRUE(surface.ok()) << surface.status().message();
  auto charts = PtexUvCharts::Build(cage, *surface);
  ASSERT_TRUE(charts.ok()) << charts.status().message();
  ASSERT_EQ(charts->num_ptex_faces(), surface->num_ptex_faces());
  BfrUvOracle oracle(cage);
  ASSERT_TRUE(oracle.ok());
  std::vector<std::array<double, 2>> points = {
      {0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.5}, {0.3, 0.8}, {0.9, 0.15}, {0.0625, 0.4375}};
  ASSERT_EQ(oracle.num_ptex_faces(), surface->num_ptex_faces());
  int compared = 0, ngon_sub_faces = 0;
  double worst = 0;
  for (int ptex = 0; ptex < surface->num_ptex_faces(); ++ptex) {
    if (surface->base_face_size(surface->base_face(PtexFaceId(ptex))) != 4) ++ngon_sub_faces;
    for (const auto& [u, v] : points) {
      double expected[2], uv[2];
      ASSERT_TRUE(oracle.Evaluate(ptex, u, v, expected)) << ptex;
      charts->Evaluate(PtexFaceId(ptex), u, v, uv);
      worst = std::max({worst, std::abs(uv[0] - expected[0]), std::abs(uv[1] - expected[1])});
      ++compared;
    }
  }
  EXPECT_EQ(compared, surface->num_ptex_faces() * static_cast<int>(points.size()));
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(ngon_sub_faces, 0) << "the cage should exercise n-gon sub-faces";
}

INSTANTIATE_TEST_SUITE_P(Cages, UvCharts,
                         ::testing::Values("meshes/keenan_spot/spot_control_mesh.obj",
                                           "meshes/opensubdiv/catmark_nonquads.obj",
                                           "meshes/jerry_the_ogre/controlmesh.obj",
                                           "image_pattern/wavy_plane.obj"),
                         [](const ::testing::TestParamInfo<const char*>& param) {
                           std::string name = std::filesystem::path(param.param).stem().string();
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

// ---- Truth files in closed form ------------------------------------------------------------

// A 256 x 256 16-bit RGB image: R ramps with the column (257 i = 65535 i / 255, exact), G with
// the row counted from the BOTTOM, B = 0. Between the first and last pixel centres, the
// luminance is exactly linear: L(s, t) = 0.2126 (256 s - 0.5) / 255 + 0.7152 (256 t - 0.5) / 255.
std::string WriteRampImage(const TempDir& dir) {
  std::vector<std::uint16_t> pixels(256 * 256 * 3);
  for (int row = 0; row < 256; ++row) {
    for (int i = 0; i < 256; ++i) {
      std::uint16_t* p = &pixels[3 * (static_cast<std::size_t>(row) * 256 + i)];
      p[0] = static_cast<std::uint16_t>(257 * i);
      p[1] = static_cast<std::uint16_t>(257 * (255 - row));
      p[2] = 0;
    }
  }
  const std::string path = dir / "ramp.png";
  WriteFile(path, EncodeWithLibpng(256, 256, PNG_FORMAT_LINEAR_RGB, pixels.data()));
  return path;
}

double RampLuminance(double s, double t) {
  return 0.2126 * (256 * s - 0.5) / 255 + 0.7152 * (256 * t - 0.5) / 255;
}

struct RampCase {
  const char* cage;
  int levels;
};

class RampTruth : public ::testing::TestWithParam<RampCase> {};

TEST_P(RampTruth, TruthIsTheClosedFormHeightAtEveryVertex) {
  TempDir dir;
  const Mesh cage = ReadCage(GetParam().cage);
  MakeSculptOptions make;
  make.cage_path = DataPath(GetParam().cage);
  make.output_path = dir / "sculpt.obj";
  make.levels = GetParam().levels;
  make.pattern = Pattern::kImage;
  make.image_path = WriteRampImage(dir);
  make.amplitude = 0.01;
  auto made = MakeSculpt(make);
  ASSERT_TRUE(made.ok()) << made.status().message();
  auto truth = ReadGroundTruth(make.output_path + ".truth");
  ASSERT_TRUE(truth.ok()) << truth.status().message();
  ASSERT_EQ(truth->size(), made->vertices);

  // The expected UV of each record from OpenSubdiv (Bfr, linear face-varying) at the
  // record's Ptex face and (u, v).
  BfrUvOracle oracle(cage);
  ASSERT_TRUE(oracle.ok());
  std::size_t checked = 0, outside = 0;
  double worst = 0;
  for (std::size_t r = 0; r < truth->size(); ++r) {
    double uv[2];
    ASSERT_TRUE(
        oracle.Evaluate(truth->faces[r].value, truth->uvs[2 * r], truth->uvs[2 * r + 1], uv));
    const double lo = 0.5 / 256, hi = 1 - 0.5 / 256;
    if (!(uv[0] >= lo && uv[0] <= hi && uv[1] >= lo && uv[1] <= hi)) {
      ++outside;  // where the repeat blends the last and first pixels: not the plane
      continue;
    }
    const double h = make.amplitude * (2 * RampLuminance(uv[0], uv[1]) - 1);
    worst = std::max(worst, std::abs(truth->h[r] - h));
    ++checked;
  }
  EXPECT_GT(checked, truth->size() * 9 / 10) << outside << " records outside the ramp's plane";
  // The truth is float: half an ulp of |h| <= A, plus the float (u, v) of the record.
  EXPECT_LT(worst, 2e-6 * make.amplitude) << "over " << checked << " records";
  EXPECT_GE(made->h_min, -make.amplitude);
  EXPECT_LE(made->h_max, make.amplitude);
  EXPECT_TRUE(std::isfinite(made->linear_error));
  EXPECT_GT(made->linear_error, 0);
}

INSTANTIATE_TEST_SUITE_P(Cages, RampTruth,
                         ::testing::Values(RampCase{"image_pattern/wavy_plane.obj", 3},
                                           RampCase{"meshes/keenan_spot/spot_control_mesh.obj", 2}),
                         [](const ::testing::TestParamInfo<RampCase>& param) {
                           return param.index == 0 ? std::string("wavy_plane")
                                                   : std::string("spot");
                         });

// ---- Errors --------------------------------------------------------------------------------

std::string MakeSculptError(const std::string& cage, const std::string& image, const TempDir& dir) {
  MakeSculptOptions make;
  make.cage_path = cage;
  make.output_path = dir / "sculpt.obj";
  make.levels = 2;
  make.pattern = Pattern::kImage;
  make.image_path = image;
  auto made = MakeSculpt(make);
  EXPECT_FALSE(made.ok());
  EXPECT_FALSE(std::filesystem::exists(make.output_path)) << "no sculpt on failure";
  if (made.ok()) return {};
  EXPECT_EQ(made.status().message().find('\n'), std::string::npos);
  return made.status().message();
}

TEST(ImagePatternErrors, OneLineNamingTheFile) {
  TempDir dir;
  const std::string spot = DataPath("meshes/keenan_spot/spot_control_mesh.obj");
  const std::string image = DataPath("image_pattern/heights.png");

  const std::string no_uvs = DataPath("meshes/opensubdiv/catmark_pole8.obj");
  std::string m = MakeSculptError(no_uvs, image, dir);
  EXPECT_EQ(m.rfind(no_uvs + ": ", 0), 0u) << m;
  EXPECT_NE(m.find("no texture coordinates"), std::string::npos) << m;

  // Some faces with vt, one without: the reader drops the UVs, the message says how many.
  const std::string mixed = dir / "mixed.obj";
  std::ofstream(mixed) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
                          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                          "f 1/1 2/2 3/3 4/4\nf 2 5 6 3\n";
  m = MakeSculptError(mixed, image, dir);
  EXPECT_EQ(m.rfind(mixed + ": face 1 has no texture coordinates (vt; 1 of 2 faces have none)", 0),
            0u)
      << m;

  const std::string missing = dir / "missing.png";
  m = MakeSculptError(spot, missing, dir);
  EXPECT_EQ(m, missing + ": no such file");

  const std::string garbage = dir / "garbage.png";
  std::ofstream(garbage) << "this is not a PNG file at all";
  m = MakeSculptError(spot, garbage, dir);
  EXPECT_EQ(m, garbage + ": not a PNG file (bad signature)");

  const std::string truncated = dir / "truncated.png";
  {
    std::ifstream in(image, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(truncated, std::ios::binary).write(bytes.data(), 300);
  }
  m = MakeSculptError(spot, truncated, dir);
  EXPECT_EQ(m.rfind(truncated + ": cannot read PNG: ", 0), 0u) << m;

  m = MakeSculptError(spot, "", dir);
  EXPECT_NE(m.find("image:FILE.png"), std::string::npos) << m;
}

TEST(ImagePatternErrors, PatternArguments) {
  auto image = ParsePatternArgument("image:some/dir/h.png");
  ASSERT_TRUE(image.ok());
  EXPECT_EQ(image->pattern, Pattern::kImage);
  EXPECT_EQ(image->image_path, "some/dir/h.png");
  auto named = ParsePatternArgument("ridges");
  ASSERT_TRUE(named.ok());
  EXPECT_EQ(named->pattern, Pattern::kRidges);
  EXPECT_TRUE(named->image_path.empty());
  EXPECT_FALSE(ParsePatternArgument("image:").ok());
  EXPECT_FALSE(ParsePatternArgument("image").ok());
  EXPECT_FALSE(ParsePattern("image").ok());
  EXPECT_FALSE(ParsePatternArgument("waves").ok());
  EXPECT_EQ(PatternName(Pattern::kImage), "image");
  PatternFrame frame;
  const float p[3] = {0, 0, 0};
  EXPECT_TRUE(std::isnan(EvaluatePattern(Pattern::kImage, frame, p)));
}

}  // namespace
}  // namespace dispex
