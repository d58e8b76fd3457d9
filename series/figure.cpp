#include "series/figure.h"

#include <fmt/core.h>

#include "core/file_io.h"

namespace ct::series {

void write_figure_page(const std::filesystem::path& dir, const Json& result) {
  std::string html = "<!doctype html><meta charset=utf-8><title>series</title><ul>";
  for (const Json& v : result["variants"]) html += fmt::format("<li>{}</li>", v["name"].get<std::string>());
  write_file_atomically(dir / "index.html", html + "</ul>\n");
}

}  // namespace ct::series
