/// \file panel_content.hpp
/// What the instruction panel says, as plain data: the VR session (vr_session.hpp) decides it,
/// panel.hpp draws it into an image and the app layer shows that image in the headset.
#pragma once

#include <string>
#include <vector>

namespace caliper::vr {

/// What the panel says.
struct PanelContent {
  std::string title;
  std::string body;                ///< word-wrapped
  std::vector<std::string> lines;  ///< extra lines (takes, results), one per row
  std::string footer;              ///< status / last feedback
  bool highlight = false;          ///< accent background (a sample was just accepted)

  bool operator==(const PanelContent& o) const {
    return title == o.title && body == o.body && lines == o.lines && footer == o.footer &&
           highlight == o.highlight;
  }
  bool operator!=(const PanelContent& o) const { return !(*this == o); }
};

}  // namespace caliper::vr
