// SPDX-License-Identifier: Apache-2.0
// Text for self-contained HTML pages: base64 against RFC 4648's test vectors, and escaping.
#include <gtest/gtest.h>

#include "core/html_text.h"

namespace ct {
namespace {

TEST(HtmlText, Base64MatchesTheRfc4648TestVectors) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\x00\x80", 3)), "/wCA");
}

TEST(HtmlText, EscapesWhatEndsTextOrAQuotedAttribute) {
  EXPECT_EQ(escape_html(R"(<a href="x">Tom & Jerry's</a>)"), "&lt;a href=&quot;x&quot;&gt;Tom &amp; Jerry&#39;s&lt;/a&gt;");
  EXPECT_EQ(escape_html("σ₁ ≥ 3 × noise"), "σ₁ ≥ 3 × noise");  // UTF-8 passes through
  // XML (SVG) allows no C0 control but tab, LF and CR, not even as a reference: each other becomes U+FFFD.
  EXPECT_EQ(escape_html(std::string("a\x01" "b\tc\nd\x1f", 8)), "a\xEF\xBF\xBD" "b\tc\nd\xEF\xBF\xBD");
}

}  // namespace
}  // namespace ct
