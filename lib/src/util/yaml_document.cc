// Bounded reading of a YAML stream's first document (yaml_document.h).
#include "util/yaml_document.h"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <sstream>
#include <string_view>

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

}  // namespace

YamlDocuments LoadYamlDocuments(const std::string& text) {
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

}  // namespace fastcal::internal
