#include "npz_reader.h"

#include <zip.h>

#include <cstring>
#include <memory>
#include <regex>
#include <stdexcept>

namespace litgs::testing {
namespace {

size_t dtype_size(const std::string& d) {
  if (d == "<f4") return 4;
  if (d == "<f8" || d == "<i8") return 8;
  if (d == "|u1") return 1;
  throw std::runtime_error("unsupported dtype " + d);
}

}  // namespace

size_t NpyArray::element_count() const {
  size_t n = 1;
  for (size_t s : shape) n *= s;
  return n;
}

std::vector<float> NpyArray::as_float() const {
  const size_t n = element_count();
  std::vector<float> out(n);
  for (size_t i = 0; i < n; ++i) {
    if (dtype == "<f4") {
      std::memcpy(&out[i], bytes.data() + 4 * i, 4);
    } else if (dtype == "<f8") {
      double d;
      std::memcpy(&d, bytes.data() + 8 * i, 8);
      out[i] = static_cast<float>(d);
    } else if (dtype == "<i8") {
      int64_t v;
      std::memcpy(&v, bytes.data() + 8 * i, 8);
      out[i] = static_cast<float>(v);
    } else {
      out[i] = bytes[i];
    }
  }
  return out;
}

int64_t NpyArray::as_scalar_int() const {
  if (dtype != "<i8" || element_count() != 1) throw std::runtime_error("array is not one int64");
  int64_t v;
  std::memcpy(&v, bytes.data(), 8);
  return v;
}

NpyArray read_npz_array(const std::string& npz_path, const std::string& name) {
  const std::string where = npz_path + ":" + name + ".npy";
  int err = 0;
  std::unique_ptr<zip_t, decltype(&zip_close)> archive(zip_open(npz_path.c_str(), ZIP_RDONLY, &err),
                                                       &zip_close);
  if (!archive)
    throw std::runtime_error(npz_path + ": cannot open as a zip archive (libzip error " +
                             std::to_string(err) + ")");
  zip_stat_t st;
  if (zip_stat(archive.get(), (name + ".npy").c_str(), 0, &st) != 0)
    throw std::runtime_error(where + ": no such array");
  std::unique_ptr<zip_file_t, decltype(&zip_fclose)> file(
      zip_fopen(archive.get(), (name + ".npy").c_str(), 0), &zip_fclose);
  if (!file) throw std::runtime_error(where + ": cannot open");
  std::vector<uint8_t> raw(st.size);
  if (zip_fread(file.get(), raw.data(), raw.size()) != static_cast<zip_int64_t>(raw.size()))
    throw std::runtime_error(where + ": truncated");
  if (raw.size() < 10 || std::memcmp(raw.data(), "\x93NUMPY", 6) != 0)
    throw std::runtime_error(where + ": not an .npy array");
  const size_t header_len = raw[6] == 1 ? size_t{raw[8]} | (size_t{raw[9]} << 8) : 0;
  if (raw[6] != 1 || 10 + header_len > raw.size())
    throw std::runtime_error(where + ": unsupported .npy version or bad header");
  const std::string header(reinterpret_cast<const char*>(raw.data() + 10), header_len);
  std::smatch m;
  if (!std::regex_search(header, m, std::regex("'descr':\\s*'([^']+)'")))
    throw std::runtime_error(where + ": no descr");
  NpyArray a;
  a.dtype = m[1];
  if (header.find("'fortran_order': False") == std::string::npos)
    throw std::runtime_error(where + ": Fortran order");
  if (!std::regex_search(header, m, std::regex("'shape':\\s*\\(([^)]*)\\)")))
    throw std::runtime_error(where + ": no shape");
  const std::string dims = m[1];
  const std::regex number("\\d+");
  for (std::sregex_iterator it(dims.begin(), dims.end(), number), end; it != end; ++it)
    a.shape.push_back(std::stoul(it->str()));
  const size_t bytes = a.element_count() * dtype_size(a.dtype);
  if (10 + header_len + bytes > raw.size()) throw std::runtime_error(where + ": data truncated");
  a.bytes.assign(raw.begin() + static_cast<long>(10 + header_len),
                 raw.begin() + static_cast<long>(10 + header_len + bytes));
  return a;
}

}  // namespace litgs::testing
