#pragma once
// A CSV file with a header line (the synthetic session's truth tables), read a row at a time.
// Fields are split at commas, without quoting (the tables we write quote nothing); every error
// is an InputError naming FILE:LINE.
#include <cstddef>
#include <fstream>
#include <string>
#include <vector>

namespace ss {

class CsvTable {
 public:
  // Opens `path` and reads its header. InputError (path, `missing`) when it cannot be opened,
  // (path, "empty") when it has no header line.
  CsvTable(const std::string& path, const std::string& missing);
  // The index of the column named `name`; InputError ("PATH:1") when the header has none.
  size_t Column(const std::string& name) const;
  // Reads the next non-empty row: false at the end of the file. InputError ("PATH:LINE") when it
  // has fewer fields than the header.
  bool Next();
  // Field `column` of the row last read.
  const std::string& operator[](size_t column) const { return fields_[column]; }
  // The row last read, as it stands in the file.
  const std::string& line() const { return line_; }
  // "PATH:LINE" of the row last read.
  std::string Where() const;

 private:
  std::string path_;
  std::ifstream in_;
  std::vector<std::string> header_;
  std::vector<std::string> fields_;
  std::string line_;
  int line_number_ = 1;
};

}  // namespace ss
