#include "blobs.hpp"

#include <algorithm>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace lampnav::vision::detail {

// The first column from u on whose pixel is bright (>= t) when `bright` is true, or dark when it
// is false; w if none. Whole blocks of the other kind are passed over 16 pixels at a time (SSE2;
// 8 elsewhere): the ceiling is mostly dark, and a lamp's rows are long bright runs.
int next_column(const std::uint8_t* row, int u, int w, std::uint8_t t, bool bright) {
#if defined(__SSE2__)
  const __m128i threshold = _mm_set1_epi8(static_cast<char>(t));
  const int passed = bright ? 0 : 0xFFFF;  // the block's bright mask when all of it is passed
  // Long stretches (the dark ceiling of a whole frame, a lamp's inside) 64 pixels at a time: the
  // brightest (or darkest) of four blocks tells whether any pixel among them is of the kind asked.
  for (; u + 64 <= w; u += 64) {
    const auto* p = reinterpret_cast<const __m128i*>(row + u);
    const __m128i x0 = _mm_loadu_si128(p), x1 = _mm_loadu_si128(p + 1);
    const __m128i x2 = _mm_loadu_si128(p + 2), x3 = _mm_loadu_si128(p + 3);
    const __m128i m = bright ? _mm_max_epu8(_mm_max_epu8(x0, x1), _mm_max_epu8(x2, x3))
                             : _mm_min_epu8(_mm_min_epu8(x0, x1), _mm_min_epu8(x2, x3));
    if ((_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_max_epu8(m, threshold), m)) ^ passed) != 0) break;
  }
  for (; u + 16 <= w; u += 16) {
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + u));
    // max(x, t) == x exactly where x >= t (unsigned).
    const int found = _mm_movemask_epi8(_mm_cmpeq_epi8(_mm_max_epu8(x, threshold), x)) ^ passed;
    if (found != 0) return u + __builtin_ctz(static_cast<unsigned>(found));  // its first pixel
  }
  if (u < w && w >= 16) {
    // The last block, read from w - 16: the pixels before u are shifted out.
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + w - 16));
    const int found = (_mm_movemask_epi8(_mm_cmpeq_epi8(_mm_max_epu8(x, threshold), x)) ^ passed) >>
                      (u - (w - 16));
    return found != 0 ? u + __builtin_ctz(static_cast<unsigned>(found)) : w;
  }
#else
  for (; u + 8 <= w; u += 8) {
    bool found = false;
    for (int k = 0; k < 8; ++k) found |= (row[u + k] >= t) == bright;
    if (found) break;
  }
#endif
  while (u < w && (row[u] >= t) != bright) ++u;
  return u;
}

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
  const PixelBox box{std::max(requested.u0, 0), std::max(requested.v0, 0),
                     std::min(requested.u1, g.width - 1), std::min(requested.v1, g.height - 1)};
  runs_.clear();
  blobs_.clear();
  sorted_.clear();
  if (box.empty()) return;
  const int w = box.u1 - box.u0 + 1, h = box.v1 - box.v0 + 1;
  const int du = box.u0, dv = box.v0;  // box -> image coordinates
  int prev_begin = 0, prev_end = 0;
  // The box's rows are asked of memory a few rows ahead of the scan: a frame just captured is
  // seldom in the cache, and a window's short rows give the hardware's prefetcher little to go on.
  const std::size_t stride = g.row_stride();
  auto prefetch_row = [&](int v) {
    const std::uint8_t* p = g.data + static_cast<std::size_t>(v + dv) * stride + du;
    for (int k = 0; k < w; k += 64) __builtin_prefetch(p + k);
    __builtin_prefetch(p + w - 1);
  };
  constexpr int kRowsAhead = 6;
  for (int v = 0; v < std::min(kRowsAhead, h); ++v) prefetch_row(v);
  for (int v = 0; v < h; ++v) {
    if (v + kRowsAhead < h) prefetch_row(v + kRowsAhead);
    const std::uint8_t* in = g.data + static_cast<std::size_t>(v + dv) * stride + du;
    const int cur_begin = static_cast<int>(runs_.size());
    int u = 0;
    while (u < w) {
      u = next_column(in, u, w, t, true);
      if (u >= w) break;
      const int start = u;
      u = next_column(in, u, w, t, false);
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
  // A blob's runs come row by row, left to right. A bright 4-neighbour above or below belongs to
  // the same blob, so a pixel is inside exactly when it is not its run's end and runs of the blob
  // cover it in the rows above and below. Counted from the runs: no pixel is read.
  auto at = [&](int k) -> const Run& { return run(b.first_run + k); };
  auto row_end = [&](int k) {  // the first run past the row of run k
    const int row = at(k).row;
    while (k < b.run_count && at(k).row == row) ++k;
    return k;
  };
  // Pixels of [u0, u1] that runs [a, a_end) and runs [c, c_end) both cover.
  auto covered_twice = [&](int u0, int u1, int a, int a_end, int c, int c_end) {
    int n = 0;
    for (; a < a_end && at(a).u0 <= u1; ++a) {
      const int a0 = std::max(u0, at(a).u0), a1 = std::min(u1, at(a).u1);
      if (a0 > a1) continue;
      while (c < c_end && at(c).u1 < a0) ++c;
      for (int k = c; k < c_end && at(k).u0 <= a1; ++k)
        n += std::max(0, std::min(a1, at(k).u1) - std::max(a0, at(k).u0) + 1);
    }
    return n;
  };
  int perimeter = 0;
  int above = 0, above_end = 0;  // the runs of the row before
  // The row's runs are [k, end), the next row's [end, next_end): each row's end found once.
  for (int k = 0, end = b.run_count > 0 ? row_end(0) : 0; k < b.run_count;) {
    const int row = at(k).row, next_end = end < b.run_count ? row_end(end) : end;
    const bool inner = above_end > above && at(above).row == row - 1 && end < b.run_count &&
                       at(end).row == row + 1;
    for (int r = k; r < end; ++r) {
      const int length = at(r).u1 - at(r).u0 + 1;
      perimeter += length;
      if (inner && length > 2)
        perimeter -= covered_twice(at(r).u0 + 1, at(r).u1 - 1, above, above_end, end, next_end);
    }
    above = k;
    above_end = end;
    k = end;
    end = next_end;
  }
  return perimeter;
}

}  // namespace lampnav::vision::detail
