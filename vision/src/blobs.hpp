#pragma once
// Bright blobs of a grey image: threshold, runs of bright pixels per row joined into 8-connected
// components by union-find. The ceiling (and the IR-filtered omni view) is mostly dark, so the
// work follows the lamps' outlines. Private to lampnav::vision; shared by both lamp detectors.

#include <cstdint>
#include <vector>

#include "lampnav/vision/image_view.hpp"

namespace lampnav::vision::detail {

// A horizontal run of bright pixels (columns u0..u1 inclusive) of one row.
struct Run {
  int row, u0, u1;
  int parent;  // union-find link while labelling
};

struct Blob {
  int pixels = 0;
  int u0 = 1 << 30, v0 = 1 << 30, u1 = -1, v1 = -1;  // bounding box, inclusive
  int first_run = 0, run_count = 0;                  // into BlobLabeller::blob_runs()
};

// The first column from u on (below w) whose pixel is bright (>= t) when `bright` is true, or
// dark when it is false; w if none. Also finds runs in a 0/1 mask (t = 1).
int next_column(const std::uint8_t* row, int u, int w, std::uint8_t t, bool bright);

class BlobLabeller {
 public:
  // Labels the pixels >= `threshold` of an 8-bit grey image of width x height. The scratch is
  // kept from call to call: no allocation once the sizes have settled.
  void label(const ImageView& grey, std::uint8_t threshold);
  // The same within `box` only (clipped to the image): runs and blobs keep the image's
  // coordinates, and pixels outside the box count as dark.
  void label(const ImageView& grey, std::uint8_t threshold, const PixelBox& box);

  const std::vector<Blob>& blobs() const { return blobs_; }
  // The runs of blob b are run(b.first_run) .. run(b.first_run + b.run_count - 1), row by row
  // and left to right within a row.
  const Run& run(int k) const { return runs_[sorted_[k]]; }
  // Blob pixels with a 4-neighbour that is dark or outside the labelled box.
  int perimeter(const Blob& b) const;

 private:
  int find_root(int i);
  std::vector<Run> runs_;
  std::vector<int> sorted_, blob_of_root_, blob_of_run_;
  std::vector<Blob> blobs_;
};

}  // namespace lampnav::vision::detail
