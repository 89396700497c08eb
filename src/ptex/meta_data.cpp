#include "ptex/meta_data.h"

#include <cstring>

#include "ptex/format.h"

namespace dispex::ptex {

std::size_t MetaElementSize(PtexMetaType type) {
  switch (type) {
    case PtexMetaType::kString:
    case PtexMetaType::kInt8:
      return 1;
    case PtexMetaType::kInt16:
      return 2;
    case PtexMetaType::kInt32:
    case PtexMetaType::kFloat:
      return 4;
    case PtexMetaType::kDouble:
      return 8;
  }
  return 1;
}

void AppendMetaRecord(const PtexMetaItem& item, std::int64_t zipsize,
                      std::vector<std::uint8_t>& out) {
  out.push_back(static_cast<std::uint8_t>(item.key.size() + 1));
  AppendBytes(out, item.key.data(), item.key.size());
  out.push_back(0);
  out.push_back(static_cast<std::uint8_t>(item.type));
  Append<std::uint32_t>(out, static_cast<std::uint32_t>(item.bytes.size()));
  if (zipsize >= 0) {
    Append<std::uint32_t>(out, static_cast<std::uint32_t>(zipsize));
  } else {
    AppendBytes(out, item.bytes.data(), item.bytes.size());
  }
}

std::string QuotedKey(const std::string& key) {
  std::string out = "'";
  for (const char c : key) out.push_back(c >= 0x20 && c < 0x7f ? c : '?');
  return out + "'";
}

std::string ParseMetaRecords(std::span<const std::uint8_t> bytes, bool large_header,
                             std::vector<ParsedMetaRecord>& out) {
  std::size_t pos = 0;
  int index = 0;
  while (pos < bytes.size()) {
    const std::string where = "item " + std::to_string(index) + " at byte " + std::to_string(pos);
    const std::size_t keysize = bytes[pos++];
    if (keysize == 0) return where + ": key size 0";
    if (bytes.size() - pos < keysize + 5 + (large_header ? 4 : 0)) {
      return where + ": record runs past the end of the block";
    }
    const char* key = reinterpret_cast<const char*>(bytes.data() + pos);
    if (key[keysize - 1] != '\0') return where + ": key is not NUL-terminated";
    ParsedMetaRecord rec;
    rec.item.key.assign(key, std::strlen(key));
    const std::string where_key = where + " (" + QuotedKey(rec.item.key) + ")";
    pos += keysize;
    const std::uint8_t type = bytes[pos++];
    if (type > 5) return where_key + ": unknown data type " + std::to_string(type);
    rec.item.type = static_cast<PtexMetaType>(type);
    rec.datasize = Load<std::uint32_t>(bytes.data() + pos);
    pos += 4;
    if (rec.datasize % MetaElementSize(rec.item.type) != 0) {
      return where_key + ": data size " + std::to_string(rec.datasize) +
             " is not a multiple of the " + std::string(PtexMetaTypeName(rec.item.type)) + " size";
    }
    if (large_header) {
      rec.zipsize = Load<std::uint32_t>(bytes.data() + pos);
      pos += 4;
      rec.item.large = true;
    } else {
      if (bytes.size() - pos < rec.datasize) {
        return where_key + ": value of " + std::to_string(rec.datasize) +
               " bytes runs past the end of the block";
      }
      rec.item.bytes.assign(bytes.begin() + static_cast<std::ptrdiff_t>(pos),
                            bytes.begin() + static_cast<std::ptrdiff_t>(pos + rec.datasize));
      pos += rec.datasize;
    }
    out.push_back(std::move(rec));
    ++index;
  }
  return {};
}

void UpsertMetaItem(std::vector<PtexMetaItem>& items, PtexMetaItem item) {
  for (PtexMetaItem& existing : items) {
    if (existing.key == item.key) {
      existing = std::move(item);
      return;
    }
  }
  items.push_back(std::move(item));
}

}  // namespace dispex::ptex
