// How a review page stores its data: binary arrays as base64 in the page's JSON, geometry in
// fixed point, and text made safe for the HTML it is put in.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dispex/mesh.h"

namespace dispex::view {

// RFC 4648 base64 with padding.
std::string Base64(std::span<const std::uint8_t> bytes);

// The bytes of an array of numbers as they lie in memory (little-endian on every machine the
// page is written on; the page's typed arrays read them so), as base64.
template <class T>
std::string Base64Of(const std::vector<T>& values) {
  return Base64({reinterpret_cast<const std::uint8_t*>(values.data()), values.size() * sizeof(T)});
}

// Points as 21-bit fixed point over their bounding box: two 32-bit words per point, x in bits
// 0-20 of the first, y in its bits 21-31 and bits 0-9 of the second, z in its bits 10-30; a
// coordinate c is min + q (max - min) / (2^21 - 1). `box` receives min x, y, z, max x, y, z.
std::vector<std::uint32_t> PackPoints(std::span<const Float3> points, double box[6]);

// Values as 16-bit signed integers: v = q scale, scale = max |value| / 32767 (0 when all are 0).
std::vector<std::int16_t> QuantizeValues(std::span<const float> values, double& scale);

// Text for an HTML element's content or an attribute: & < > " ' escaped.
std::string EscapeHtml(std::string_view text);

// JSON text put inside <script type="application/json">: every '<' written as \u003c, so no
// "</script" or "<!--" can end or change the element (a '<' is only ever inside a JSON string).
std::string ScriptSafeJson(std::string_view json);

}  // namespace dispex::view
