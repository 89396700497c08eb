#include "options.h"

#include <fmt/format.h>

#include <string>

#include "errors.h"

namespace dispex::python {

namespace {

// An int (not a bool, not a float) for `name`.
long long Integer(const py::handle& value, const std::string& name) {
  if (!py::isinstance<py::int_>(value) || py::isinstance<py::bool_>(value)) {
    throw py::value_error(
        fmt::format("{}: {} is not an integer", name, py::repr(value).cast<std::string>()));
  }
  return value.cast<long long>();
}

}  // namespace

void SetExtractOptions(ExtractOptions& options, const py::dict& kwargs) {
  py::object dumps = py::module_::import("json").attr("dumps");
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    if (name == "threads") {
      const long long threads = Integer(value, name);
      if (threads < 0 || threads > 4096) {
        throw py::value_error(fmt::format("threads = {}: must be 0 (all cores) to 4096", threads));
      }
      options.threads = static_cast<int>(threads);
    } else if (name == "max_memory") {
      const long long bytes = Integer(value, name);
      if (bytes < 0) throw py::value_error(fmt::format("max_memory = {}: must be >= 0", bytes));
      options.max_memory = static_cast<std::uint64_t>(bytes);
    } else if (name == "incremental") {
      if (!py::isinstance<py::bool_>(value)) {
        throw py::value_error(fmt::format("incremental: {} is not True or False",
                                          py::repr(value).cast<std::string>()));
      }
      options.incremental = value.cast<bool>();
    } else if (name == "shard") {
      if (!py::isinstance<py::str>(value)) {
        throw py::value_error(
            fmt::format("shard: {} is not a string \"I/N\"", py::repr(value).cast<std::string>()));
      }
      CheckArgument(ParseShard(value.cast<std::string>(), options.shard_index, options.shard_count)
                        .WithPrefix("shard"));
    } else if (name == "shard_sculpt") {
      if (!py::isinstance<py::str>(value)) {
        throw py::value_error(fmt::format("shard_sculpt: {} is not \"whole\" or \"part\"",
                                          py::repr(value).cast<std::string>()));
      }
      StatusOr<ShardSculpt> kind = ParseShardSculpt(value.cast<std::string>());
      CheckArgument(kind.status().WithPrefix("shard_sculpt"));
      options.shard_sculpt = *kind;
    } else {
      std::string json;
      try {
        json = dumps(value).cast<std::string>();
      } catch (const py::error_already_set&) {
        throw py::value_error(fmt::format("{}: {} is not a number or a string", name,
                                          py::repr(value).cast<std::string>()));
      }
      const Status set = SetExtractOption(options, name, json);
      if (!set.ok() && set.message().rfind(name + ": unknown option", 0) == 0) {
        throw py::value_error(
            fmt::format("{}: unknown option (known: {}, threads, incremental, shard, shard_sculpt)",
                        name, ExtractOptionNames()));
      }
      CheckArgument(set);
    }
  }
}

}  // namespace dispex::python
