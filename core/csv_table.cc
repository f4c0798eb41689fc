#include "core/csv_table.h"

#include <sstream>

#include "core/error.h"

namespace ss {
namespace {

void Split(const std::string& line, std::vector<std::string>* out) {
  out->clear();
  std::stringstream ss(line);
  std::string field;
  while (std::getline(ss, field, ',')) out->push_back(field);
}

}  // namespace

CsvTable::CsvTable(const std::string& path, const std::string& missing) : path_(path), in_(path) {
  if (!in_) throw InputError(path, missing);
  if (!std::getline(in_, line_)) throw InputError(path, "empty");
  Split(line_, &header_);
}

size_t CsvTable::Column(const std::string& name) const {
  for (size_t k = 0; k < header_.size(); ++k) {
    if (header_[k] == name) return k;
  }
  throw InputError(path_ + ":1", "no column '" + name + "' in the header");
}

bool CsvTable::Next() {
  while (std::getline(in_, line_)) {
    ++line_number_;
    if (line_.empty()) continue;
    Split(line_, &fields_);
    if (fields_.size() < header_.size()) {
      throw InputError(Where(), "expected " + std::to_string(header_.size()) + " fields, got " +
                                    std::to_string(fields_.size()));
    }
    return true;
  }
  return false;
}

std::string CsvTable::Where() const { return path_ + ":" + std::to_string(line_number_); }

}  // namespace ss
