// The report document (internal/report_document.h) rendered as Markdown (report.md: plain
// text a person reads and diffs) and as one self-contained HTML page (report.html,
// design.html, the solve plot: inline CSS and SVG, no scripts or external files). The
// content is built once (report.cc, design_output.cc, trajectory_plot.cc); only the markup
// differs.
#include <string>
#include <vector>

#include "fastcal/internal/report_document.h"
#include "fastcal/svg_plot.h"

namespace fastcal {
namespace {

using internal::Block;
using internal::Document;
using internal::Span;
using internal::Table;
using internal::Text;

// ---------------------------------------------------------------------------------------
// Markdown.

// Escapes what would start markup in running text (no text here starts a line with
// '#', '>' or '-', and no link reference is ever defined, so brackets are safe); '|' only
// inside a table cell.
std::string MarkdownEscape(const std::string& s, bool in_table) {
  std::string out;
  for (char c : s) {
    if (c == '\\' || c == '`' || c == '*' || c == '_' || c == '<' || (in_table && c == '|')) {
      out += '\\';
    }
    out += c == '\n' ? ' ' : c;
  }
  return out;
}

std::string MarkdownCode(std::string s, bool in_table) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  // A fence longer than the longest run of backticks inside.
  size_t longest = 0, run = 0;
  for (char c : s) {
    run = c == '`' ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  const std::string fence(longest + 1, '`');
  const bool pad = !s.empty() && (s.front() == '`' || s.back() == '`');
  // Inside a table a '|' ends the cell even in a code span; GFM accepts "\|" there.
  std::string body;
  for (char c : s) body += in_table && c == '|' ? std::string("\\|") : std::string(1, c);
  return fence + (pad ? " " : "") + body + (pad ? " " : "") + fence;
}

std::string MarkdownInline(const Text& text, bool in_table = false) {
  std::string out;
  for (const Span& s : text.spans()) {
    switch (s.kind) {
      case Span::kPlain:
        out += MarkdownEscape(s.text, in_table);
        break;
      case Span::kCode:
        out += MarkdownCode(s.text, in_table);
        break;
      case Span::kBold:
        out += "**" + MarkdownEscape(s.text, in_table) + "**";
        break;
      case Span::kSwatch:
        break;
    }
  }
  return out;
}

std::string MarkdownFence(const std::string& body) {
  size_t longest = 0, run = 0;
  for (char c : body) {
    run = c == '`' ? run + 1 : 0;
    longest = std::max(longest, run);
  }
  return std::string(std::max<size_t>(3, longest + 1), '`');
}

}  // namespace

std::string internal::RenderMarkdown(const Document& doc) {
  std::string out;
  for (const Block& b : doc.blocks()) {
    if (b.target == Target::kHtmlOnly) continue;
    switch (b.kind) {
      case Block::kHeading:
        out += std::string(b.level, '#') + " " + MarkdownInline(b.text) + "\n\n";
        break;
      case Block::kParagraph:
        out += MarkdownInline(b.text) + "\n\n";
        break;
      case Block::kList:
        for (const Text& item : b.items) out += "- " + MarkdownInline(item) + "\n";
        out += "\n";
        break;
      case Block::kTable: {
        const Table& t = b.table;
        if (!t.caption.spans().empty()) out += "**" + MarkdownInline(t.caption) + "**\n\n";
        out += "|";
        for (const Text& h : t.header) out += " " + MarkdownInline(h, true) + " |";
        out += "\n|";
        for (size_t c = 0; c < t.header.size(); ++c) {
          out += c < t.right_align.size() && t.right_align[c] ? " ---: |" : " --- |";
        }
        out += "\n";
        for (const auto& row : t.rows) {
          out += "|";
          for (const Text& cell : row) out += " " + MarkdownInline(cell, true) + " |";
          out += "\n";
        }
        out += "\n";
        break;
      }
      case Block::kPre: {
        if (!b.text.spans().empty()) out += "**" + MarkdownInline(b.text) + "**\n\n";
        std::string body = b.pre;
        if (!body.empty() && body.back() != '\n') body += '\n';
        const std::string fence = MarkdownFence(body);
        out += fence + "\n" + body + fence + "\n\n";
        break;
      }
      case Block::kFigure:
        break;
      case Block::kBanner:
        out += "> " + MarkdownInline(b.text) + "\n\n";
        break;
    }
  }
  while (out.size() >= 2 && out[out.size() - 1] == '\n' && out[out.size() - 2] == '\n') {
    out.pop_back();
  }
  return out;
}

namespace {

// ---------------------------------------------------------------------------------------
// HTML.

constexpr char kCss[] = R"(
body { margin: 0; background: #f4f5f7; color: #1d1f23;
  font: 14px/1.5 "Helvetica Neue", Arial, sans-serif; }
main { max-width: 1120px; margin: 0 auto; padding: 24px 32px 48px; background: #fff; }
h1 { font-size: 26px; margin: 8px 0 4px; }
h2 { font-size: 19px; margin: 32px 0 10px; padding-bottom: 4px; border-bottom: 2px solid #d7dbe0; }
p { margin: 8px 0; max-width: 980px; }
ul { margin: 6px 0 10px; padding-left: 22px; }
code, pre { font: 12.5px/1.4 "DejaVu Sans Mono", Menlo, Consolas, monospace; }
code { background: #f0f1f3; padding: 0 3px; border-radius: 3px; overflow-wrap: anywhere; }
td code, th code { overflow-wrap: normal; }  /* names whole; long commands wrap at spaces */
pre { background: #f6f7f9; border: 1px solid #e1e4e8; padding: 10px 12px; overflow-x: auto; }
table { border-collapse: collapse; margin: 8px 0 18px; font-variant-numeric: tabular-nums; }
.table-scroll { max-width: 100%; overflow-x: auto; }
caption { caption-side: top; text-align: left; font-weight: bold; padding: 4px 0; }
th, td { border: 1px solid #d7dbe0; padding: 3px 9px; vertical-align: top; }
th { background: #eef0f3; text-align: left; font-weight: 600; }
td.num, th.num { text-align: right; white-space: nowrap; }
tbody tr:nth-child(even) { background: #fafbfc; }
.sw { display: inline-block; width: 10px; height: 10px; margin-right: 6px; border-radius: 2px; }
figure { margin: 12px 0 22px; }
figure .charts { display: flex; flex-wrap: wrap; gap: 12px 16px; }
figure svg { max-width: 100%; height: auto; }
figcaption { color: #555; font-size: 13px; margin-top: 4px; }
details { margin: 8px 0; }
.banner { margin: 12px 0 14px; padding: 10px 14px; border-left: 6px solid; border-radius: 3px;
  font-size: 15px; max-width: 980px; }
.banner-good { background: #e7f4ea; border-color: #2e7d32; }
.banner-caution { background: #fff4d6; border-color: #e0a000; }
.banner-bad { background: #fde8e6; border-color: #c62828; }
.banner-info { background: #e8f0fa; border-color: #1f5fa8; }
summary { cursor: pointer; font-weight: 600; }
@media print {
  body { background: #fff; font-size: 11px; }
  main { max-width: none; padding: 0; }
  details::details-content { content-visibility: visible; display: block; }
  details > * { display: block; }
  pre, code { white-space: pre-wrap; overflow-wrap: anywhere; }
  table, figure, pre { break-inside: avoid; }
  .table-scroll { overflow-x: visible; }
  h2 { break-after: avoid; }
}
)";

std::string HtmlInline(const Text& text) {
  std::string out;
  for (const Span& s : text.spans()) {
    switch (s.kind) {
      case Span::kPlain:
        out += XmlEscape(s.text);
        break;
      case Span::kCode:
        out += "<code>" + XmlEscape(s.text) + "</code>";
        break;
      case Span::kBold:
        out += "<strong>" + XmlEscape(s.text) + "</strong>";
        break;
      case Span::kSwatch:
        out += "<span class=\"sw\" style=\"background:" + XmlEscape(s.text) + "\"></span>";
        break;
    }
  }
  return out;
}

const char* ToneClass(internal::Tone tone) {
  switch (tone) {
    case internal::Tone::kGood:
      return "banner banner-good";
    case internal::Tone::kCaution:
      return "banner banner-caution";
    case internal::Tone::kBad:
      return "banner banner-bad";
    case internal::Tone::kInfo:
      break;
  }
  return "banner banner-info";
}

}  // namespace

std::string internal::RenderHtmlPage(const Document& doc) {
  std::string out =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
      XmlEscape(doc.title) + "</title>\n<style>" + kCss + "</style>\n</head>\n<body>\n<main>\n";
  for (const Block& b : doc.blocks()) {
    if (b.target == Target::kMarkdownOnly) continue;
    switch (b.kind) {
      case Block::kHeading: {
        const std::string tag = "h" + Int(std::clamp(b.level, 1, 6));
        out += "<" + tag + ">" + HtmlInline(b.text) + "</" + tag + ">\n";
        break;
      }
      case Block::kParagraph:
        out += "<p>" + HtmlInline(b.text) + "</p>\n";
        break;
      case Block::kList:
        out += "<ul>\n";
        for (const Text& item : b.items) out += "<li>" + HtmlInline(item) + "</li>\n";
        out += "</ul>\n";
        break;
      case Block::kTable: {
        const Table& t = b.table;
        auto cls = [&t](size_t c) {
          return c < t.right_align.size() && t.right_align[c] ? " class=\"num\"" : "";
        };
        // Wide tables (the budget's columns per consider group) scroll inside the page on a
        // narrow window instead of running past it.
        out += "<div class=\"table-scroll\">\n<table>\n";
        if (!t.caption.spans().empty()) out += "<caption>" + HtmlInline(t.caption) + "</caption>\n";
        out += "<thead><tr>";
        for (size_t c = 0; c < t.header.size(); ++c) {
          out += std::string("<th") + cls(c) + ">" + HtmlInline(t.header[c]) + "</th>";
        }
        out += "</tr></thead>\n<tbody>\n";
        for (const auto& row : t.rows) {
          out += "<tr>";
          for (size_t c = 0; c < row.size(); ++c) {
            out += std::string("<td") + cls(c) + ">" + HtmlInline(row[c]) + "</td>";
          }
          out += "</tr>\n";
        }
        out += "</tbody>\n</table>\n</div>\n";
        break;
      }
      case Block::kPre:
        if (b.collapsed) {
          out += "<details>\n<summary>" + HtmlInline(b.text) + "</summary>\n<pre>" +
                 XmlEscape(b.pre) + "</pre>\n</details>\n";
        } else {
          if (!b.text.spans().empty())
            out += "<p><strong>" + HtmlInline(b.text) + "</strong></p>\n";
          out += "<pre>" + XmlEscape(b.pre) + "</pre>\n";
        }
        break;
      case Block::kFigure:
        out += "<figure>\n<div class=\"charts\">\n";
        for (const std::string& svg : b.svgs) out += svg + "\n";
        out += "</div>\n<figcaption>" + HtmlInline(b.text) + "</figcaption>\n</figure>\n";
        break;
      case Block::kBanner:
        out += std::string("<div class=\"") + ToneClass(b.tone) + "\">" + HtmlInline(b.text) +
               "</div>\n";
        break;
    }
  }
  out += "</main>\n</body>\n</html>\n";
  return out;
}

}  // namespace fastcal
