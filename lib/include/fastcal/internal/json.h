// A minimal JSON writer (objects, arrays, strings, finite numbers) for the CLI's and the
// report's machine-readable outputs. Non-finite numbers are written as null: JSON has no
// NaN, and a reader must not mistake a missing value for a number.
#ifndef FASTCAL_INTERNAL_JSON_H_
#define FASTCAL_INTERNAL_JSON_H_

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "fastcal/internal/number_text.h"

namespace fastcal {

class JsonWriter {
 public:
  explicit JsonWriter(int indent = 2) : indent_(indent) {}

  JsonWriter& BeginObject() { return Open('{'); }
  JsonWriter& EndObject() { return Close('}'); }
  JsonWriter& BeginArray() { return Open('['); }
  JsonWriter& EndArray() { return Close(']'); }
  // Inside an object: the next value's key.
  JsonWriter& Key(const std::string& key) {
    Separate();
    out_ += Quote(key) + (indent_ > 0 ? ": " : ":");
    after_key_ = true;
    return *this;
  }
  JsonWriter& String(const std::string& value) {
    Separate();
    out_ += Quote(value);
    return *this;
  }
  JsonWriter& Number(double value) {
    Separate();
    if (!std::isfinite(value)) {
      out_ += "null";
    } else {
      out_ += value == 0.0 ? "0" : internal::FormatDouble("%.12g", value);  // never "-0"
    }
    return *this;
  }
  // All 17 significant digits (%.17g): reads back to the same double, for values another
  // run reads (a change's time, fastcal calibrate --sessions-at=summary.json).
  JsonWriter& ExactNumber(double value) {
    Separate();
    if (!std::isfinite(value)) {
      out_ += "null";
    } else {
      out_ += value == 0.0 ? "0" : internal::FormatDouble("%.17g", value);
    }
    return *this;
  }
  JsonWriter& Int(long long value) {
    Separate();
    out_ += std::to_string(value);
    return *this;
  }
  JsonWriter& Bool(bool value) {
    Separate();
    out_ += value ? "true" : "false";
    return *this;
  }
  JsonWriter& Null() {
    Separate();
    out_ += "null";
    return *this;
  }
  template <typename Container>
  JsonWriter& NumberArray(const Container& values) {
    BeginArray();
    const int saved = indent_;
    indent_ = 0;  // short numeric arrays on one line
    for (double v : values) Number(v);
    indent_ = saved;
    inline_close_ = true;
    return EndArray();
  }
  const std::string& str() const { return out_; }
  // The text written since the last Take, removed from the writer (the nesting stays):
  // a document streamed a piece at a time is the same bytes as str() of it whole.
  std::string Take() {
    std::string text;
    text.swap(out_);
    return text;
  }

  static std::string Quote(const std::string& s) {
    std::string q = "\"";
    for (unsigned char c : s) {
      switch (c) {
        case '"':
          q += "\\\"";
          break;
        case '\\':
          q += "\\\\";
          break;
        case '\n':
          q += "\\n";
          break;
        case '\r':
          q += "\\r";
          break;
        case '\t':
          q += "\\t";
          break;
        default:
          if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof(buf), "\\u%04x", c);
            q += buf;
          } else {
            q += static_cast<char>(c);
          }
      }
    }
    return q + "\"";
  }

 private:
  JsonWriter& Open(char c) {
    Separate();
    out_ += c;
    first_.push_back(true);
    return *this;
  }
  JsonWriter& Close(char c) {
    const bool empty = first_.back();
    first_.pop_back();
    if (!empty && indent_ > 0 && !inline_close_) Newline();
    inline_close_ = false;
    out_ += c;
    if (first_.empty()) out_ += '\n';
    return *this;
  }
  void Separate() {
    if (after_key_) {
      after_key_ = false;
      return;
    }
    if (first_.empty()) return;
    if (!first_.back()) out_ += indent_ > 0 ? "," : ", ";
    first_.back() = false;
    if (indent_ > 0) Newline();
  }
  void Newline() { out_ += '\n' + std::string(indent_ * first_.size(), ' '); }

  int indent_;
  std::string out_;
  std::vector<bool> first_;
  bool after_key_ = false;
  bool inline_close_ = false;
};

}  // namespace fastcal

#endif  // FASTCAL_INTERNAL_JSON_H_
