// The viewer's settings panel (Dear ImGui): method, depth, background, colors, point size and shape,
// dilation, eye-dome lighting, level of detail, camera views, keyframes, screenshots and
// live statistics. Built once per shown frame; edits go to a copy of the settings that the caller hands
// to Session::setSettings, which renders only when something really changed.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "view/session.h"

namespace pointrast::view {

struct PanelInfo {
  std::string device;
  std::string input;
  uint64_t points = 0;
  std::vector<Method> methods; // the methods this device runs
  std::string pathFile;
  std::string annotationsFile; // where Save writes the measurements; empty: no Save
  std::string picked;          // the last pick, as lines of attributes
  std::string exported;        // the last export's file and points, or why it failed
  // The clip box as typed (min then max corner, six numbers), kept between frames.
  std::array<char, 256> clipBoxText{};
  // The profile: its line as typed (x1,y1,x2,y2,...), the strip's width, the last cut's message, and the
  // size of the picture shown in the Profile window (0: none yet).
  std::array<char, 2048> profileLineText{};
  std::array<char, 1024> profileFileText{}; // where the exports go (the button sets the extension); empty:
                                            // beside the screenshots
  double profileWidth = 1;
  std::string profileStatus;
  uint32_t profileImageWidth = 0, profileImageHeight = 0;
};

struct PanelActions {
  bool screenshot = false;
  bool frameAll = false;
  bool addKeyframe = false;
  bool clearKeyframes = false;
  std::optional<StandardView> view;
  bool saveMeasurements = false;
  std::optional<size_t> deleteMeasurement;
  bool exportLas = false; // write the points the clip box keeps (with the clip mode) as LAS
  bool profile = false;   // cut the profile of the typed line and width, and show it
  bool profileLas = false, profileCsv = false, profilePng = false; // write the profile's points or picture
};

// Screen rectangles (x, y, width, height in pixels) of the panel's controls by label, for --events.
using PanelItems = std::map<std::string, std::array<float, 4>>;

PanelActions buildPanel(Session& session, PanelInfo& info, ViewSettings& settings, PanelItems& items);

} // namespace pointrast::view
