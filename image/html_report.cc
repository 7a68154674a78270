#include "image/html_report.h"

#include "core/errors.h"

namespace handlabel {

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Base64Encode(const std::string& bytes) {
  static const char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v =
        (uint8_t(bytes[i]) << 16) | (uint8_t(bytes[i + 1]) << 8) | uint8_t(bytes[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += kAlphabet[(v >> s) & 63];
  }
  const size_t rest = bytes.size() - i;
  if (rest > 0) {
    uint32_t v = uint8_t(bytes[i]) << 16;
    if (rest == 2) v |= uint8_t(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string PngDataUri(const ImageU8& image) {
  return "data:image/png;base64," + Base64Encode(EncodePng(image));
}

HtmlPage::HtmlPage(std::string title) : title_(std::move(title)) {}

void HtmlPage::Heading(const std::string& text, int level) {
  HL_CHECK(level >= 1 && level <= 6, "heading level 1-6");
  const std::string tag = "h" + std::to_string(level);
  body_ += "<" + tag + ">" + HtmlEscape(text) + "</" + tag + ">\n";
}

void HtmlPage::Paragraph(const std::string& text) {
  body_ += "<p>" + HtmlEscape(text) + "</p>\n";
}

void HtmlPage::Preformatted(const std::string& text) {
  body_ += "<pre>" + HtmlEscape(text) + "</pre>\n";
}

void HtmlPage::Table(const HtmlTable& t) {
  body_ += "<table" + (t.id.empty() ? "" : " id=\"" + HtmlEscape(t.id) + "\"") +
           ">\n<thead><tr>";
  for (const std::string& h : t.header) body_ += "<th>" + HtmlEscape(h) + "</th>";
  body_ += "</tr></thead>\n<tbody>\n";
  for (const std::vector<HtmlCell>& row : t.rows) {
    body_ += "<tr>";
    for (const HtmlCell& cell : row) {
      std::string attributes;
      if (!cell.json_path.empty()) {
        attributes = " data-json=\"" + HtmlEscape(cell.json_path) +
                     "\" data-decimals=\"" + std::to_string(cell.decimals) + "\"";
      }
      body_ += "<td" + attributes + ">" + HtmlEscape(cell.text) + "</td>";
    }
    body_ += "</tr>\n";
  }
  body_ += "</tbody></table>\n";
}

void HtmlPage::Image(const ImageU8& image, const std::string& caption) {
  body_ += "<figure><img src=\"" + PngDataUri(image) + "\" alt=\"" + HtmlEscape(caption) +
           "\" width=\"" + std::to_string(image.width) + "\"><figcaption>" +
           HtmlEscape(caption) + "</figcaption></figure>\n";
}

std::string HtmlPage::ToString() const {
  // Inline CSS only: the page must render the same offline.
  static const char kStyle[] =
      "body{font-family:sans-serif;margin:2em;max-width:1400px;color:#222}"
      "table{border-collapse:collapse;margin:1em 0}"
      "th,td{border:1px solid #bbb;padding:3px 8px;text-align:right}"
      "th{background:#eee}td:first-child{text-align:left}"
      "figure{margin:1em 0}img{max-width:100%;height:auto;border:1px solid #ddd}"
      "figcaption{font-size:90%;color:#555}pre{background:#f6f6f6;padding:8px;"
      "overflow-x:auto}";
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<title>" +
         HtmlEscape(title_) + "</title>\n<style>" + kStyle +
         "</style>\n</head>\n<body>\n<h1>" + HtmlEscape(title_) + "</h1>\n" + body_ +
         "</body>\n</html>\n";
}

}  // namespace handlabel
