#include "run_mask.hpp"

#include <algorithm>

namespace lampnav::vision::detail {

void RunMask::reset(int width, int height) {
  width_ = width;
  height_ = height;
  spans_.clear();
  start_.clear();
}

namespace {

// Along rows: a pixel k in [r, w - r) is set after erosion when all of k - r .. k + r are, after
// dilation when any is; the pixels nearer the edge are cleared.
void along_rows(const RunMask& in, int r, bool erode, RunMask& out) {
  const int w = in.width();
  out.reset(w, in.height());
  for (int y = 0; y < in.height(); ++y) {
    out.begin_row();
    bool open = false;
    Span cur;
    for (const Span* s = in.row_begin(y); s != in.row_end(y); ++s) {
      const int a = erode ? s->a + r : std::max(s->a - r, r);
      const int b = erode ? s->b - r : std::min(s->b + r, w - 1 - r);
      if (a > b) continue;
      if (open && a <= cur.b + 1) {  // dilated spans that touch become one
        cur.b = std::max(cur.b, b);
        continue;
      }
      if (open) out.add(cur.a, cur.b);
      cur = {a, b};
      open = true;
    }
    if (open) out.add(cur.a, cur.b);
  }
  out.end_rows();
}

// x = x AND row (sorted, disjoint spans).
void intersect(std::vector<Span>& x, const Span* first, const Span* last, std::vector<Span>& tmp) {
  tmp.clear();
  const Span* p = first;
  for (std::size_t i = 0; i < x.size() && p != last;) {
    const int a = std::max(x[i].a, p->a), b = std::min(x[i].b, p->b);
    if (a <= b) tmp.push_back({a, b});
    if (x[i].b < p->b) {
      ++i;
    } else {
      ++p;
    }
  }
  x.swap(tmp);
}

// Along columns: row y in [r, h - r) is the AND (erosion) or OR (dilation) of rows y - r .. y + r;
// the rows nearer the edge are empty.
void along_columns(const RunMask& in, int r, bool erode, RunMask& out, std::vector<Span>& x,
                   std::vector<Span>& tmp) {
  const int h = in.height();
  out.reset(in.width(), h);
  for (int y = 0; y < h; ++y) {
    out.begin_row();
    if (y < r || y >= h - r) continue;
    x.assign(in.row_begin(y - r), in.row_end(y - r));
    if (erode) {
      for (int j = y - r + 1; j <= y + r && !x.empty(); ++j)
        intersect(x, in.row_begin(j), in.row_end(j), tmp);
    } else {
      for (int j = y - r + 1; j <= y + r; ++j) x.insert(x.end(), in.row_begin(j), in.row_end(j));
      std::sort(x.begin(), x.end(), [](const Span& s, const Span& t) { return s.a < t.a; });
    }
    // Sorted; spans that overlap or touch are joined (only a union has any).
    bool open = false;
    Span cur;
    for (const Span& s : x) {
      if (open && s.a <= cur.b + 1) {
        cur.b = std::max(cur.b, s.b);
        continue;
      }
      if (open) out.add(cur.a, cur.b);
      cur = s;
      open = true;
    }
    if (open) out.add(cur.a, cur.b);
  }
  out.end_rows();
}

}  // namespace

void RunOpening::open(const RunMask& in, int r, RunMask& out) {
  along_rows(in, r, true, rows_);
  along_columns(rows_, r, true, eroded_, a_, b_);
  along_rows(eroded_, r, false, dilated_rows_);
  along_columns(dilated_rows_, r, false, out, a_, b_);
}

}  // namespace lampnav::vision::detail
