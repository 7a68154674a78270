#include <gtest/gtest.h>

#include "image/html_report.h"
#include "image/image.h"

namespace handlabel {
namespace {

TEST(Base64, Rfc4648TestVectors) {
  EXPECT_EQ(Base64Encode(""), "");
  EXPECT_EQ(Base64Encode("f"), "Zg==");
  EXPECT_EQ(Base64Encode("fo"), "Zm8=");
  EXPECT_EQ(Base64Encode("foo"), "Zm9v");
  EXPECT_EQ(Base64Encode("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64Encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64Encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64Encode(std::string("\xff\x00\x80", 3)), "/wCA");
}

TEST(HtmlEscape, EscapesMarkupAndQuotes) {
  EXPECT_EQ(HtmlEscape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;");
}

TEST(HtmlPage, TablesNameTheirNumbersAndImagesAreInline) {
  HtmlPage page("t <1>");
  HtmlTable table;
  table.id = "results";
  table.header = {"method", "MPJPE"};
  table.rows = {{{"a&b"}, {"3.14", "methods.0.metrics.mpjpe_mm", 2}}};
  page.Table(table);
  page.Image(ImageU8(2, 1, 3, 7), "two pixels");
  const std::string html = page.ToString();
  EXPECT_NE(html.find("<title>t &lt;1&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("<td>a&amp;b</td>"), std::string::npos);
  EXPECT_NE(html.find("<td data-json=\"methods.0.metrics.mpjpe_mm\" "
                      "data-decimals=\"2\">3.14</td>"),
            std::string::npos);
  const std::string uri = PngDataUri(ImageU8(2, 1, 3, 7));
  EXPECT_EQ(uri.rfind("data:image/png;base64,iVBORw0KGgo", 0), 0u);  // PNG signature
  EXPECT_NE(html.find("<img src=\"" + uri + "\""), std::string::npos);
  EXPECT_EQ(html.find("http"), std::string::npos);  // nothing to fetch
}

}  // namespace
}  // namespace handlabel
