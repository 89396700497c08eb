// Meta data item records (docs/ptex.md, "Meta data records"): encoding for the writer,
// parsing for the reader.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dispex/ptex.h"

namespace dispex::ptex {

// Bytes of one value of the type (a string's unit is a byte).
std::size_t MetaElementSize(PtexMetaType type);

// Appends `keysize, key, datatype, datasize` and then the value (small items) or the
// value's compressed size (large-item header records, `zipsize` >= 0).
void AppendMetaRecord(const PtexMetaItem& item, std::int64_t zipsize,
                      std::vector<std::uint8_t>& out);

struct ParsedMetaRecord {
  PtexMetaItem item;  // for large-item headers, `bytes` stays empty
  std::uint32_t datasize = 0;
  std::uint32_t zipsize = 0;  // large-item headers only
};

// Parses every record of an inflated small meta data block (`large_header` false) or large
// meta data header (true). Returns an empty string, or what is wrong and at which record.
std::string ParseMetaRecords(std::span<const std::uint8_t> bytes, bool large_header,
                             std::vector<ParsedMetaRecord>& out);

// A key as messages show it, quoted: bytes outside printable ASCII become '?', so a key
// read from a file cannot break a message's single line.
std::string QuotedKey(const std::string& key);

// Inserts or replaces (keeping the position) an item by key.
void UpsertMetaItem(std::vector<PtexMetaItem>& items, PtexMetaItem item);

}  // namespace dispex::ptex
