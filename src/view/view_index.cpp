// MakeViewIndex: the page that lists a batch's review pages.

#include "dispex/version.h"
#include "dispex/view.h"
#include "view/embedded_assets.h"
#include "view/page_data.h"

namespace dispex {

std::string MakeViewIndex(const std::string& title, const std::vector<ViewIndexEntry>& entries) {
  std::string rows;
  for (const ViewIndexEntry& e : entries) {
    const std::string name = view::EscapeHtml(e.name);
    rows += "<tr class=\"" + view::EscapeHtml(e.status) + "\"><td>";
    rows += e.page.empty() ? name : "<a href=\"" + view::EscapeHtml(e.page) + "\">" + name + "</a>";
    rows += "</td><td>" + view::EscapeHtml(e.status) + "</td><td>" + view::EscapeHtml(e.note) +
            "</td></tr>\n";
  }
  std::string html(view::EmbeddedAsset(view::Asset::kIndexHtml));
  auto replace = [&](std::string_view marker, const std::string& by) {
    for (std::size_t at = html.find(marker); at != std::string::npos;
         at = html.find(marker, at + by.size())) {
      html.replace(at, marker.size(), by);
    }
  };
  const std::string escaped = view::EscapeHtml(title);
  replace("@TITLE@", escaped);
  replace("@HEADING@", escaped);
  replace("@CSS@", std::string(view::EmbeddedAsset(view::Asset::kViewerCss)));
  replace("@GENERATOR@", view::EscapeHtml(std::string("dispex ") + Version()));
  replace("@ROWS@", rows);
  return html;
}

}  // namespace dispex
