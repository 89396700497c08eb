// TracerOptions::isa and DISPEX_EMBREE_ISA: every ISA this CPU runs builds, is named in the
// backend string and gives the same hits to the bit; an unknown ISA or one the CPU lacks is a
// one-line error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <optional>
#include <random>
#include <string>

#include "dispex/trace.h"
#include "test_meshes.h"

namespace dispex {
namespace {

using trace_test::Vec3;

Mesh Blub() {
  return trace_test::LoadObj(DISPEX_TEST_DATA_DIR "/meshes/keenan_blub/blub_control_mesh.obj");
}

TEST(IsaTest, EverySupportedIsaIsNamedInTheBackend) {
  const Mesh mesh = Blub();
  ASSERT_FALSE(SupportedEmbreeIsas().empty());
  for (const std::string_view isa : SupportedEmbreeIsas()) {
    TracerOptions options;
    options.isa = std::string(isa);
    auto tracer = MakeEmbreeTracer(mesh, options);
    ASSERT_TRUE(tracer.ok()) << tracer.status().message();
    EXPECT_NE((*tracer)->stats().backend.find("(" + options.isa + ", forced)"), std::string::npos)
        << (*tracer)->stats().backend;
  }
}

TEST(IsaTest, UnknownOrUnsupportedIsaIsAOneLineError) {
  const Mesh mesh = Blub();
  TracerOptions options;
  options.isa = "avx3";
  auto tracer = MakeEmbreeTracer(mesh, options);
  ASSERT_FALSE(tracer.ok());
  EXPECT_EQ(tracer.status().message(),
            "isa 'avx3': unknown Embree ISA (valid: sse2, sse4.2, avx, avx2, avx512)");
  const auto supported = SupportedEmbreeIsas();
  for (const std::string_view isa : EmbreeIsaNames()) {
    if (std::find(supported.begin(), supported.end(), isa) != supported.end()) continue;
    options.isa = std::string(isa);  // e.g. avx512 on an AVX2 machine
    tracer = MakeEmbreeTracer(mesh, options);
    ASSERT_FALSE(tracer.ok()) << isa;
    const std::string& message = tracer.status().message();
    EXPECT_EQ(message.rfind("isa '" + options.isa + "': this CPU lacks", 0), 0u) << message;
    EXPECT_NE(message.find("RTC_ERROR_UNSUPPORTED_CPU"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

// Sets an environment variable for the scope of a test and restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (old_) {
      ::setenv(name_, old_->c_str(), 1);
    } else {
      ::unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(IsaTest, EnvironmentChoosesTheIsaUnlessTheOptionDoes) {
  const Mesh mesh = Blub();
  {
    ScopedEnv env("DISPEX_EMBREE_ISA", "sse4.2");
    auto tracer = MakeEmbreeTracer(mesh);
    ASSERT_TRUE(tracer.ok()) << tracer.status().message();
    EXPECT_NE((*tracer)->stats().backend.find("(sse4.2, forced)"), std::string::npos)
        << (*tracer)->stats().backend;
    TracerOptions options;
    options.isa = "sse2";
    tracer = MakeEmbreeTracer(mesh, options);
    ASSERT_TRUE(tracer.ok()) << tracer.status().message();
    EXPECT_NE((*tracer)->stats().backend.find("(sse2, forced)"), std::string::npos)
        << (*tracer)->stats().backend;
  }
  {
    ScopedEnv env("DISPEX_EMBREE_ISA", "fast");
    auto tracer = MakeEmbreeTracer(mesh);
    ASSERT_FALSE(tracer.ok());
    EXPECT_EQ(tracer.status().message().rfind("DISPEX_EMBREE_ISA 'fast': unknown Embree ISA", 0),
              0u)
        << tracer.status().message();
  }
  {
    ScopedEnv env("DISPEX_EMBREE_ISA", "");
    auto tracer = MakeEmbreeTracer(mesh);
    ASSERT_TRUE(tracer.ok()) << tracer.status().message();
    const std::string& backend = (*tracer)->stats().backend;
    EXPECT_EQ(backend.find("forced"), std::string::npos) << backend;
    // Embree's own choice is the widest ISA the CPU runs.
    EXPECT_NE(backend.find("(" + std::string(SupportedEmbreeIsas().back()) + ")"),
              std::string::npos)
        << backend;
  }
}

// Rays and normal queries in every RayMode hit or miss alike under every ISA this CPU runs
// (rays aimed at vertices and edges included), with bit-identical t on the same primitive;
// where another ISA's Embree picked another face at a vertex or edge, t agrees to 1e-5.
TEST(IsaTest, SameHitsUnderEveryIsa) {
  const Mesh mesh = Blub();
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  std::vector<Ray> rays;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 o{0.8 * g(rng), 0.8 * g(rng), 0.8 * g(rng)};
    const Vec3 d{g(rng), g(rng), g(rng)};
    rays.push_back(Ray{trace_test::ToFloat3(o), 0, trace_test::ToFloat3(d), 50});
  }
  // Rays at vertices and edge midpoints, from the centroid.
  Vec3 centre{0, 0, 0};
  for (const Float3& p : mesh.positions) {
    centre = centre + (1.0 / static_cast<double>(mesh.num_vertices())) * trace_test::ToVec3(p);
  }
  for (std::size_t f = 0; f < mesh.num_faces(); f += 3) {
    const auto face = mesh.face(f);
    const Vec3 a = trace_test::ToVec3(mesh.positions[face[0]]);
    const Vec3 b = trace_test::ToVec3(mesh.positions[face[1]]);
    rays.push_back(Ray{trace_test::ToFloat3(centre), 0, trace_test::ToFloat3(a - centre), 10});
    rays.push_back(
        Ray{trace_test::ToFloat3(centre), 0, trace_test::ToFloat3(0.5 * (a + b) - centre), 10});
  }
  std::vector<Float3> origins, normals;
  for (const Ray& r : rays) {
    origins.push_back(r.origin);
    normals.push_back(r.direction);
  }
  const std::size_t n = rays.size();
  struct Answers {
    std::vector<RayHit> hits;
    std::vector<float> t;
    std::vector<SculptPrimId> prim;
    std::vector<std::uint8_t> flags;
  };
  for (const RayMode mode : {RayMode::kSingle, RayMode::kPacket8, RayMode::kPacket16}) {
    std::optional<Answers> first;
    std::string first_isa;
    for (const std::string_view isa : SupportedEmbreeIsas()) {
      TracerOptions options;
      options.isa = std::string(isa);
      options.ray_mode = mode;
      auto tracer = MakeEmbreeTracer(mesh, options);
      ASSERT_TRUE(tracer.ok()) << tracer.status().message();
      Answers a{std::vector<RayHit>(n), std::vector<float>(n), std::vector<SculptPrimId>(n),
                std::vector<std::uint8_t>(n)};
      TraceCounters counters;
      (*tracer)->Intersect(rays, a.hits, counters);
      (*tracer)->TraceNormals(origins, normals, NormalQuery{0.5f}, NormalHits{a.t, a.prim, a.flags},
                              counters);
      if (!first) {
        first = std::move(a);
        first_isa = std::string(isa);
        continue;
      }
      int differ = 0, other_face = 0;
      auto same_t = [&](float t, float t0, bool same_prim) {
        if (same_prim) return t == t0;
        ++other_face;
        return std::fabs(t - t0) <= 1e-5f * std::max(1.0f, std::fabs(t0));
      };
      for (std::size_t i = 0; i < n; ++i) {
        const RayHit& h = a.hits[i];
        const RayHit& h0 = first->hits[i];
        bool same = h.hit() == h0.hit() && a.flags[i] == first->flags[i];
        if (same && h.hit()) same = same_t(h.t, h0.t, h.prim == h0.prim);
        if (same && a.flags[i] != 0) {
          same = same_t(a.t[i], first->t[i], a.prim[i] == first->prim[i]);
        }
        if (!same && ++differ <= 5) {
          ADD_FAILURE() << RayModeName(mode) << " " << isa << " vs " << first_isa << ", ray " << i
                        << ": t " << h.t << " vs " << h0.t << ", normal t " << a.t[i] << " vs "
                        << first->t[i];
        }
      }
      EXPECT_EQ(differ, 0) << RayModeName(mode) << " " << isa << " vs " << first_isa;
      // Another face is the exception: at vertices and edges only.
      EXPECT_LE(other_face, 40) << RayModeName(mode) << " " << isa << " vs " << first_isa;
    }
  }
}

}  // namespace
}  // namespace dispex
