// Bounded reading of a YAML stream's first document (yaml_document.h).
#include "util/yaml_document.h"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <string_view>
#include <vector>

#include "fastcal/internal/quote.h"

namespace fastcal::internal {
namespace {

// Notes where a document starts and counts its events; throws past a budget, so that a
// parser that emits events without consuming text cannot run away either.
class DocumentProbe : public YAML::EventHandler {
 public:
  explicit DocumentProbe(size_t budget) : budget_(budget) {}

  const YAML::Mark& start() const { return start_; }
  const YAML::Mark& first_event() const { return first_event_; }

  void OnDocumentStart(const YAML::Mark& mark) override { start_ = mark; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { Count(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { Count(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    Count(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    Count(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Count(mark);
  }
  void OnMapEnd() override {}

 private:
  void Count(const YAML::Mark& mark) {
    if (events_ == 0) first_event_ = mark;
    if (++events_ > budget_) {
      throw YAML::ParserException(mark, "the parser does not advance (too many YAML events)");
    }
  }

  size_t budget_;
  size_t events_ = 0;
  YAML::Mark start_;
  YAML::Mark first_event_;
};

// Each event stands for at least one token of text, except the empty values a mapping
// or sequence may hold, one per token at most: a generous bound.
size_t EventBudget(const std::string& text) { return 4 * text.size() + 64; }

[[noreturn]] void ThrowStuck(const std::string& text, const YAML::Mark& mark) {
  const size_t pos = mark.pos < 0 ? 0 : static_cast<size_t>(mark.pos);
  const std::string_view rest = std::string_view(text).substr(std::min(pos, text.size()));
  const std::string_view token = rest.substr(0, rest.empty() ? 0 : 1);
  throw YAML::ParserException(
      mark, "unexpected " + Quote(token) + " at column " + std::to_string(mark.column + 1) +
                ": the document cannot go on from here" +
                (token == "," ? " (a stray comma outside any [list] or {mapping}?)" : ""));
}

// Refuses text nested deeper than kMaxYamlDepth before yaml-cpp sees it, in one pass and
// no memory: yaml-cpp 0.7 tokenizes a whole flow collection before its parser's own depth
// guard acts (16 MiB of '[' took 3.9 GB and 13 s, then "bad file"). The depth at a point
// is the block levels open (indentations, and "- " entries started on one line) plus the
// flow brackets open; quoted scalars and comments are skipped. A bracket inside a plain
// scalar ("a[1]") counts too: harmless, it closes again.
void CheckNestingDepth(const std::string& text) {
  std::vector<size_t> indents;  // of the open block levels
  int flow = 0;
  int line = 0;
  size_t i = 0;
  const auto refuse = [&](size_t at, size_t line_start) {
    YAML::Mark mark;
    mark.pos = static_cast<int>(at);
    mark.line = line;
    mark.column = static_cast<int>(at - line_start);
    throw YAML::ParserException(
        mark, "nesting deeper than " + std::to_string(kMaxYamlDepth) +
                  " levels (a model or spec file nests at most 6): not a fastcal file?");
  };
  while (i < text.size()) {
    const size_t line_start = i;
    size_t indent = 0;
    for (; i < text.size() && text[i] == ' '; ++i) ++indent;
    int sequence_entries = 0;  // "- - - x": levels opened on this line
    if (flow == 0 && i < text.size() && text[i] != '\n' && text[i] != '#' && text[i] != '\r') {
      while (!indents.empty() && indents.back() > indent) indents.pop_back();
      if (indents.empty() || indents.back() < indent) indents.push_back(indent);
      while (i + 1 < text.size() && text[i] == '-' && (text[i + 1] == ' ' || text[i + 1] == '\t')) {
        ++sequence_entries;
        i += 2;
        while (i < text.size() && text[i] == ' ') ++i;
      }
    }
    const int block = static_cast<int>(indents.size()) + sequence_entries;
    if (block > kMaxYamlDepth) refuse(i, line_start);
    for (; i < text.size() && text[i] != '\n'; ++i) {
      const char c = text[i];
      if (c == '#' && (i == line_start || text[i - 1] == ' ' || text[i - 1] == '\t')) {
        while (i < text.size() && text[i] != '\n') ++i;
        break;
      }
      if (c == '"' || c == '\'') {
        // A quoted scalar (possibly over several lines): to its closing quote.
        for (++i; i < text.size(); ++i) {
          if (text[i] == '\n') ++line;
          if (c == '"' && text[i] == '\\') {
            ++i;
          } else if (text[i] == c) {
            if (c == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {
              ++i;
            } else {
              break;
            }
          }
        }
        continue;
      }
      if (c == '[' || c == '{') {
        if (block + ++flow > kMaxYamlDepth) refuse(i, line_start);
      } else if ((c == ']' || c == '}') && flow > 0) {
        --flow;
      }
    }
    ++i;  // the newline
    ++line;
  }
}

}  // namespace

YamlDocuments LoadYamlDocuments(const std::string& text) {
  CheckNestingDepth(text);
  YamlDocuments result;
  std::stringstream stream(text);
  YAML::Parser parser(stream);
  // Three documents tell one from several, and a second document that starts where the
  // first did, or a third where the second did, is the parser standing still.
  YAML::Mark previous_start;
  for (int document = 0; document < 3; ++document) {
    DocumentProbe probe(EventBudget(text));
    if (!parser.HandleNextDocument(probe)) break;
    if (document > 0 && probe.start().pos == previous_start.pos) ThrowStuck(text, probe.start());
    if (document == 1) result.second_line = probe.first_event().line + 1;
    previous_start = probe.start();
    result.count = std::min(document + 1, 2);
  }
  // The probe above has shown that the first document ends; YAML::Load parses exactly
  // that document again, now into nodes.
  if (result.count > 0) result.first = YAML::Load(text);
  return result;
}

std::string ShortestNumber(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

int LineOf(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.line < 0 ? 0 : mark.line + 1;
}

bool YamlErrorRecorder::Fail(int line, const std::string& path, const std::string& what) {
  error_ = source_;
  if (line > 0) error_ += ":" + std::to_string(line);
  // Key names come from the file: escaped like the values (internal/quote.h).
  error_ += ": " + Escape(path) + ": " + what;
  return false;
}

bool YamlErrorRecorder::FailFile(const std::string& what) {
  error_ = source_ + ": " + what;
  return false;
}

}  // namespace fastcal::internal
