// SPDX-License-Identifier: Apache-2.0
#pragma once
// Text for self-contained HTML pages (the analyzer's report, the series' figure page): escaping and the
// base64 of data: URIs.

#include <string>
#include <string_view>

namespace ct {

// &, <, >, " and ' as character references: safe in element text and in quoted attributes, of HTML and of XML
// (SVG). Control characters XML does not allow (C0 but tab, LF, CR) become U+FFFD.
std::string escape_html(std::string_view text);

// RFC 4648 base64 with padding.
std::string base64(std::string_view bytes);

}  // namespace ct
