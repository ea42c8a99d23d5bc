#include "blobs.hpp"

#include <algorithm>
#include <cstring>

namespace lampnav::vision::detail {

int BlobLabeller::find_root(int i) {
  while (runs_[i].parent != i) {
    runs_[i].parent = runs_[runs_[i].parent].parent;  // path halving
    i = runs_[i].parent;
  }
  return i;
}

void BlobLabeller::label(const ImageView& g, std::uint8_t t) {
  label(g, t, PixelBox{0, 0, g.width - 1, g.height - 1});
}

void BlobLabeller::label(const ImageView& g, std::uint8_t t, const PixelBox& requested) {
  box_ = {std::max(requested.u0, 0), std::max(requested.v0, 0), std::min(requested.u1, g.width - 1),
          std::min(requested.v1, g.height - 1)};
  runs_.clear();
  blobs_.clear();
  sorted_.clear();
  width_ = 0;
  if (box_.empty()) return;
  const int w = box_.u1 - box_.u0 + 1, h = box_.v1 - box_.v0 + 1;
  const int du = box_.u0, dv = box_.v0;  // box -> image coordinates
  width_ = w;
  binary_.resize(static_cast<std::size_t>(w) * h);
  for (int v = 0; v < h; ++v) {  // a plain loop the compiler vectorizes; no thread pool
    const std::uint8_t* __restrict in =
        g.data + static_cast<std::size_t>(v + dv) * g.row_stride() + du;
    std::uint8_t* __restrict out = binary_.data() + static_cast<std::size_t>(v) * w;
    for (int u = 0; u < w; ++u) out[u] = in[u] >= t ? 1 : 0;
  }
  int prev_begin = 0, prev_end = 0;
  for (int v = 0; v < h; ++v) {
    const std::uint8_t* b = binary_.data() + static_cast<std::size_t>(v) * w;
    const int cur_begin = static_cast<int>(runs_.size());
    int u = 0;
    while (u < w) {
      while (u + 8 <= w) {  // skip the dark eight pixels at a time
        std::uint64_t word;
        std::memcpy(&word, b + u, 8);
        if (word != 0) break;
        u += 8;
      }
      while (u < w && b[u] == 0) ++u;
      if (u >= w) break;
      const int start = u;
      while (u < w && b[u] != 0) ++u;
      const int id = static_cast<int>(runs_.size());
      runs_.push_back({v + dv, start + du, u - 1 + du, id});
    }
    const int cur_end = static_cast<int>(runs_.size());
    int j0 = prev_begin;
    for (int c = cur_begin; c < cur_end; ++c) {
      while (j0 < prev_end && runs_[j0].u1 < runs_[c].u0 - 1) ++j0;  // (image coordinates)
      for (int j = j0; j < prev_end && runs_[j].u0 <= runs_[c].u1 + 1; ++j) {
        const int ra = find_root(j), rb = find_root(c);
        if (ra != rb) runs_[std::max(ra, rb)].parent = std::min(ra, rb);
      }
    }
    prev_begin = cur_begin;
    prev_end = cur_end;
  }
  // Blobs, and their runs grouped together (counting sort by blob).
  blobs_.clear();
  blob_of_root_.assign(runs_.size(), -1);
  blob_of_run_.resize(runs_.size());
  for (std::size_t i = 0; i < runs_.size(); ++i) {
    const int r = find_root(static_cast<int>(i));
    if (blob_of_root_[r] < 0) {
      blob_of_root_[r] = static_cast<int>(blobs_.size());
      blobs_.emplace_back();
    }
    Blob& c = blobs_[blob_of_root_[r]];
    const Run& run = runs_[i];
    c.pixels += run.u1 - run.u0 + 1;
    c.u0 = std::min(c.u0, run.u0);
    c.u1 = std::max(c.u1, run.u1);
    c.v0 = std::min(c.v0, run.row);
    c.v1 = std::max(c.v1, run.row);
    ++c.run_count;
    blob_of_run_[i] = blob_of_root_[r];
  }
  int offset = 0;
  for (auto& c : blobs_) {
    c.first_run = offset;
    offset += c.run_count;
    c.run_count = 0;
  }
  sorted_.resize(runs_.size());
  for (std::size_t i = 0; i < runs_.size(); ++i) {
    Blob& c = blobs_[blob_of_run_[i]];
    sorted_[c.first_run + c.run_count++] = static_cast<int>(i);
  }
}

int BlobLabeller::perimeter(const Blob& b) const {
  int n = 0;
  for (int k = 0; k < b.run_count; ++k) {
    const Run& r = run(b.first_run + k);
    for (int u = r.u0; u <= r.u1; ++u)
      if (u == r.u0 || u == r.u1 || !bright(u, r.row - 1) || !bright(u, r.row + 1)) ++n;
  }
  return n;
}

}  // namespace lampnav::vision::detail
