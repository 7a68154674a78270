#pragma once
// Self-contained HTML pages (reports): one file with inline CSS and images embedded as
// data: URIs, so it opens anywhere without network access or files beside it. A small
// builder: headings, paragraphs, preformatted text, tables and images, appended in
// order. Table cells can name the JSON number they show (data-json attributes) so that
// a checker (tools/browser/check-report.mjs) reads the numbers back and compares them
// with the JSON they came from.

#include <string>
#include <utility>
#include <vector>

#include "image/image.h"

namespace handlabel {

// Text with &, <, >, " and ' escaped for HTML content and attribute values.
std::string HtmlEscape(const std::string& text);

// Standard base64 (RFC 4648, with '=' padding).
std::string Base64Encode(const std::string& bytes);

// "data:image/png;base64,..." of the image encoded as PNG.
std::string PngDataUri(const ImageU8& image);

// A table cell. A cell showing a number of a JSON document names it: json_path is
// the dotted path of the number in that document ("methods.0.metrics.mpjpe_mm") and
// decimals how it was rounded; written as data-json / data-decimals attributes.
struct HtmlCell {
  HtmlCell(std::string text_in = "") : text(std::move(text_in)) {}  // NOLINT: implicit
  HtmlCell(std::string text_in, std::string json_path_in, int decimals_in)
      : text(std::move(text_in)),
        json_path(std::move(json_path_in)),
        decimals(decimals_in) {}
  std::string text;       // escaped when written
  std::string json_path;  // "" = not a checked number
  int decimals = 0;
};

struct HtmlTable {
  std::string id;                   // the table's id attribute ("" = none)
  std::vector<std::string> header;  // column titles
  std::vector<std::vector<HtmlCell>> rows;
};

class HtmlPage {
 public:
  explicit HtmlPage(std::string title);
  void Heading(const std::string& text, int level = 2);
  void Paragraph(const std::string& text);
  void Preformatted(const std::string& text);
  void Table(const HtmlTable& table);
  // A figure with the image inline (data: URI) and a caption.
  void Image(const ImageU8& image, const std::string& caption);
  // The whole document.
  std::string ToString() const;

 private:
  std::string title_;
  std::string body_;
};

}  // namespace handlabel
