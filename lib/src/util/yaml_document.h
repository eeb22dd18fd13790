// The one YAML document of a model or spec file, read without yaml-cpp 0.7's hang.
//
// YAML::LoadAll in yaml-cpp 0.7 (Debian 12) never returns, and grows without bound, on a
// stream the parser cannot advance through, e.g. a lone "," or "{a: 1}, {b: 2}": each
// call of Parser::HandleNextDocument reports an empty document without consuming the
// offending token, and LoadAll calls it again (upstream issue #1040, fixed by pull
// request #1319 after 0.7). LoadYamlDocuments asks the parser for at most three
// documents, notices a document that starts where the previous one started (the parser
// made no progress) and reports the token there as a syntax error. Private to the
// library: the header needs yaml-cpp, which is a private dependency.
#ifndef FASTCAL_SRC_YAML_DOCUMENT_H_
#define FASTCAL_SRC_YAML_DOCUMENT_H_

#include <yaml-cpp/yaml.h>

#include <string>
#include <utility>

namespace fastcal::internal {

// Deepest nesting LoadYamlDocuments reads (block levels plus flow brackets); a model or
// spec nests at most 6.
inline constexpr int kMaxYamlDepth = 32;

struct YamlDocuments {
  // The first document (Null when the text has none: empty, or only comments).
  YAML::Node first;
  // 0, 1, or 2 meaning two or more.
  int count = 0;
  // 1-based line where the second document starts (when count == 2).
  int second_line = 0;
};

// Reads `text`, as YAML::LoadAll would, but returns in bounded time and memory on any
// input. Text nested deeper than kMaxYamlDepth is refused first, in one linear pass
// ("nesting deeper than 32 levels ...", at the line where it goes past). Throws YAML::Exception
// (with the mark of the problem) on a syntax error, including the text yaml-cpp 0.7 would loop on:
// "unexpected ',' after the end of the document" at its line and column.
YamlDocuments LoadYamlDocuments(const std::string& text);

// The shortest decimal text that reads back to exactly `value` (at most 17 significant
// digits, std::to_chars), so that a model or spec file written and read again is
// bit-exact; YAML's ".nan", ".inf" and "-.inf" for the others.
std::string ShortestNumber(double value);

// 1-based line of a node, or 0 when yaml-cpp does not know it.
int LineOf(const YAML::Node& node);

// The error of a strict reader of a model, spec or column map (each derives from it), as
// "<source>:<line>: <key path>: <what>".
class YamlErrorRecorder {
 public:
  explicit YamlErrorRecorder(std::string source) : source_(std::move(source)) {}

  const std::string& error() const { return error_; }

  // Records "<source>:<line>: <path>: <what>" (":<line>" left out when 0); false, for
  // `return Fail(...)`.
  bool Fail(int line, const std::string& path, const std::string& what);
  // Records "<source>: <what>": a problem of the whole file.
  bool FailFile(const std::string& what);

 private:
  std::string source_;
  std::string error_;
};

}  // namespace fastcal::internal

#endif  // FASTCAL_SRC_YAML_DOCUMENT_H_
