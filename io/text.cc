#include "io/text.h"

#include <charconv>
#include <cmath>

#include "io/error.h"

namespace litgs::io {

LineReader::LineReader(std::filesystem::path path) : path_(std::move(path)) {
  if (!std::filesystem::exists(path_)) fail(path_, 0, "file does not exist");
  in_.open(path_, std::ios::binary);
  if (!in_) fail(path_, 0, "cannot open for reading");
}

bool LineReader::next(std::string& line) {
  if (!std::getline(in_, line)) return false;
  ++line_;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

std::vector<std::string_view> split_ws(std::string_view s) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t') ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

std::string_view trim(std::string_view s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split_char(std::string_view s, char delimiter) {
  std::vector<std::string_view> out;
  size_t start = 0;
  while (true) {
    const size_t end = s.find(delimiter, start);
    out.push_back(
        trim(s.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start)));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return out;
}

bool is_blank_or_comment(std::string_view s) {
  s = trim(s);
  return s.empty() || s.front() == '#';
}

bool try_parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);  // from_chars rejects a leading '+'
  if (token.empty()) return false;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && ptr == token.data() + token.size() && std::isfinite(value);
}

double parse_double(std::string_view token, const std::filesystem::path& file, int64_t line,
                    std::string_view what) {
  double value = 0;
  if (!try_parse_double(token, value)) {
    std::string t(token);
    const bool nonfinite = t.find("nan") != std::string::npos || t.find("NaN") != std::string::npos ||
                           t.find("inf") != std::string::npos || t.find("Inf") != std::string::npos;
    fail(file, line,
         std::string(what) + ": " + (nonfinite ? "non-finite value '" : "not a number: '") + t + "'");
  }
  return value;
}

int64_t parse_int(std::string_view token, const std::filesystem::path& file, int64_t line,
                  std::string_view what, int64_t lo, int64_t hi) {
  int64_t value = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || ptr != token.data() + token.size() || token.empty())
    fail(file, line, std::string(what) + ": not an integer: '" + std::string(token) + "'");
  if (value < lo || value > hi)
    fail(file, line,
         std::string(what) + ": " + std::to_string(value) + " is outside [" + std::to_string(lo) + ", " +
             std::to_string(hi) + "]");
  return value;
}

std::string format_double(double x) {
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof(buf), x);
  return std::string(buf, ec == std::errc() ? ptr : buf);
}

}  // namespace litgs::io
