// The reflection lobe of a ViewSource as a triangle mesh, and the camera that frames it.
//
// The lobe is a deformed hemisphere over the outgoing directions ω_out(θo, φo) of the local
// frame (docs/design.md §4: z is the normal, directions point away from the surface, the light is
// at (θin, φin = 0), i.e. in the +x half of the xz-plane, so the mirror direction is (θin, 180°)).
// The vertex in direction ω_out sits at distance r(ω_out) from the origin:
//   linear scale: r = q,  log scale: r = max(0, log10(q / q_floor))  (in decades),
// where q = f_r (1/sr, not multiplied by cosθ) or, with `cosine_weighted`, f_r·cosθo, of the
// chosen channel. f_r is the LUT sampled as a GPU samples it (brdf::Lut::SampleAngles), so for
// a θin between two measured slices the lobe is exactly the one the LUT interpolates.
// Geometry only: no VTK here, so it can be tested and timed on its own.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "brdf/core/geometry.h"
#include "brdf/viewer/view_source.h"

namespace brdf::viewer {

enum class Channel { kRed, kGreen, kBlue, kLuminance };
const char* ChannelName(Channel channel);  // "R", "G", "B", "luminance"
// The channel's value of an RGB f_r; luminance is Rec.709 Y = 0.2126 R + 0.7152 G + 0.0722 B.
double ChannelValue(const float* rgb, Channel channel);

enum class RadiusScale { kLinear, kLog };

struct LobeOptions {
  double theta_in_deg = 0;  // light polar angle, any value in [0°, 90°)
  Channel channel = Channel::kLuminance;
  bool cosine_weighted = false;  // radius from f_r·cosθo instead of f_r
  RadiusScale scale = RadiusScale::kLinear;
  // Log scale only: q_floor in the units of q (1/sr). 0 picks 10^-3 of the mesh's largest q;
  // the viewer passes one floor for both sources of a comparison so their radii agree.
  double log_floor = 0;
  int theta_rows = 90;  // rows of vertices from θo = 0° to 90° (row t at θo = t·90°/theta_rows)
  int phi_columns = 180;  // columns at φo = c·360°/phi_columns

  // Throws InvalidArgument naming the bad field.
  void Validate() const;
};

struct LobeMesh {
  int theta_rows = 0, phi_columns = 0;
  // (theta_rows + 1) × phi_columns vertices, index t·phi_columns + c. Row 0 is the pole: its
  // vertices are one direction and coincide (kept so every row has the same layout).
  std::vector<Vec3> directions;  // unit ω_out of each vertex
  std::vector<Vec3> points;      // r(ω_out)·ω_out
  std::vector<double> values;    // q at each vertex (1/sr): what the colour shows
  std::vector<Coverage> coverage;
  // Triangles over the vertex grid (counter-clockwise seen from outside), and for each the
  // worst coverage of its three vertices (unmeasured > extrapolated > measured).
  std::vector<std::array<int, 3>> triangles;
  std::vector<Coverage> triangle_coverage;
  double max_value = 0;   // largest q
  double max_radius = 0;  // largest r
  double log_floor = 0;   // q_floor used (log scale), 0 for linear

  // Frame arrows for the light at θin: unit vectors.
  Vec3 normal{0, 0, 1}, light{0, 0, 1}, mirror{0, 0, 1};
  int FarthestVertex() const;  // index of the vertex with the largest r
};

LobeMesh BuildLobe(const ViewSource& source, const LobeOptions& options);

// A perspective camera (what vtkCamera takes), with the vertical view angle.
struct CameraSetup {
  Vec3 position, focal_point, view_up;
  double view_angle_deg = 30;  // vertical
};

// The camera the lobe view starts with: looking at the centre of the box that holds the lobe
// and its arrows (`extent` along each of them from the origin) from azimuth −90° (the −y side,
// so the plane of incidence faces the viewer) and 25° elevation, far enough that the box's
// bounding sphere fits both the vertical and the horizontal view angle for `aspect` = W/H.
CameraSetup LobeCamera(const LobeMesh& mesh, double arrow_length, double aspect);

}  // namespace brdf::viewer
