// The brdf-view window: lobes, slice heat maps and the environment-lit preview of one source
// (and optionally a second one to compare), interactive or rendered once to a PNG.
//
// Sources arrive already opened (tools/brdf-view opens them through the project's one way of
// opening files); a source that failed to open arrives as its error message, which the window
// shows instead of crashing. VTK stays behind this header.
//
// Keys (also listed in the window, toggled with h):
//   h help            q / Esc quit          s screenshot (brdf-view-N.png in the current folder)
//   1 / 2 / 3 mode: lobe, slices, preview
//   Left / Right  θin −/+ 1°   Page Up / Page Down  previous / next measured slice
//   a all slices at once       c channel (R, G, B, luminance)
//   l linear / log radius      w radius f_r or f_r·cosθo      m compare: wireframe / colour
//   r reset camera             e / E rotate the environment (preview)
//   preview: arrow keys or a mouse drag orbit the camera; the picture refines while idle
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "brdf/core/brdf_source.h"
#include "brdf/viewer/view_source.h"

namespace brdf::viewer {

enum class Mode { kLobe, kSlices, kPreview };
const char* ModeName(Mode mode);  // "lobe", "slices", "preview"
// "lobe", "slices", "preview"; throws InvalidArgument listing them.
Mode ModeFromName(const std::string& name);

// One source as the window receives it: either opened, or the reason it could not be.
struct LoadedSource {
  std::string path;                        // as the user typed it
  std::optional<ViewSource> view;          // lobes and slices
  std::shared_ptr<const BrdfSource> brdf;  // what the preview renders (may be null)
  std::string error;                       // non-empty when opening failed
};

struct ViewerOptions {
  Mode mode = Mode::kLobe;
  double theta_in_deg = 0;  // starting light angle
  int width = 960, height = 720;
  // Starting state of the toggles (the keys c, l, w, a change them in the window).
  int channel = 3;               // 0 R, 1 G, 2 B, 3 luminance
  bool log_scale = false;        // lobe radius and colours on a log scale
  bool cosine_weighted = false;  // lobe radius f_r·cosθo
  bool all_slices = false;       // every measured slice at once
  // Non-empty: render once to this PNG and return, without waiting for input. A JSON file
  // `<screenshot>.json` beside it records the camera (position, focal point, view up, vertical
  // view angle in degrees) and the image size, so a report (or a test) can tell what is where.
  std::string screenshot_path;
  // Called on the calling thread when the run reaches a milestone, in this order: "window"
  // (the X window and its OpenGL context exist), "sources opened" (both sources are open or
  // have failed), "scene" (the first picture's actors are built, nothing drawn yet), "first
  // frame" (the first picture is rendered and the X server has processed it: in a window it is
  // on screen; for a screenshot it is in VTK's off-screen framebuffer), "screenshot" (the PNG
  // and its camera file are written). For start-up timing (docs/benchmarks.md); may be empty.
  std::function<void(const char* milestone)> on_milestone;

  // Throws InvalidArgument naming the bad field (size outside 64…8192, θin outside [0°, 90°)).
  void Validate() const;
};

struct ViewerResult {
  bool ok = true;               // false when a source failed to open or the screenshot failed
  std::string message;          // what to tell the user on failure (one line)
  bool display_failed = false;  // the X display could not be opened (worth another try)
};

// Empty when an X display can be opened; otherwise one sentence saying why not ($DISPLAY unset,
// or the display named cannot be opened). VTK on Debian needs X for any rendering.
std::string DisplayProblem();

// Opens one source (never throws: a failure is LoadedSource::error). Called on a thread of its
// own, so it must not touch X or VTK.
using SourceOpener = std::function<LoadedSource()>;

// Opens the window (or renders the screenshot). Blocks until the user closes the window.
// The sources are opened on other threads while the window and its OpenGL context are
// created, so that neither waits for the other before the first frame; `open_compare` may be
// empty (no second source). Both openers have returned when RunViewer returns.
// Throws InvalidArgument for bad options; rendering problems come back in the result.
ViewerResult RunViewer(const ViewerOptions& options, const SourceOpener& open_primary,
                       const SourceOpener& open_compare);

}  // namespace brdf::viewer
