#include "view/page_data.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dispex::view {

std::string Base64(std::span<const std::uint8_t> bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t w = (std::uint32_t(bytes[i]) << 16) | (std::uint32_t(bytes[i + 1]) << 8) |
                            std::uint32_t(bytes[i + 2]);
    out += kAlphabet[(w >> 18) & 63];
    out += kAlphabet[(w >> 12) & 63];
    out += kAlphabet[(w >> 6) & 63];
    out += kAlphabet[w & 63];
  }
  if (const std::size_t rest = bytes.size() - i; rest > 0) {
    std::uint32_t w = std::uint32_t(bytes[i]) << 16;
    if (rest == 2) w |= std::uint32_t(bytes[i + 1]) << 8;
    out += kAlphabet[(w >> 18) & 63];
    out += kAlphabet[(w >> 12) & 63];
    out += rest == 2 ? kAlphabet[(w >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::vector<std::uint32_t> PackPoints(std::span<const Float3> points, double box[6]) {
  constexpr double kMax = (1 << 21) - 1;
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  if (!points.empty()) {
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::numeric_limits<double>::infinity();
      hi[c] = -std::numeric_limits<double>::infinity();
    }
    for (const Float3& p : points) {
      const double xyz[3] = {p.x, p.y, p.z};
      for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], xyz[c]), hi[c] = std::max(hi[c], xyz[c]);
    }
  }
  for (int c = 0; c < 3; ++c) box[c] = lo[c], box[3 + c] = hi[c];
  std::vector<std::uint32_t> out(2 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double xyz[3] = {points[i].x, points[i].y, points[i].z};
    std::uint32_t q[3];
    for (int c = 0; c < 3; ++c) {
      const double span = hi[c] - lo[c];
      const double t = span > 0 ? (xyz[c] - lo[c]) / span : 0;
      q[c] = static_cast<std::uint32_t>(std::lround(std::clamp(t, 0.0, 1.0) * kMax));
    }
    out[2 * i] = q[0] | (q[1] << 21);
    out[2 * i + 1] = (q[1] >> 11) | (q[2] << 10);
  }
  return out;
}

std::vector<std::int16_t> QuantizeValues(std::span<const float> values, double& scale) {
  double m = 0;
  for (float v : values) m = std::max(m, std::fabs(double(v)));
  scale = m > 0 ? m / 32767 : 0;
  std::vector<std::int16_t> out(values.size(), 0);
  if (scale == 0) return out;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const long q = std::lround(double(values[i]) / scale);
    out[i] = static_cast<std::int16_t>(std::clamp(q, -32767L, 32767L));
  }
  return out;
}

std::string EscapeHtml(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string ScriptSafeJson(std::string_view json) {
  std::string out;
  out.reserve(json.size());
  for (char c : json) {
    if (c == '<') {
      out += "\\u003c";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace dispex::view
