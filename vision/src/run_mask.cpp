#include "run_mask.hpp"

#include <algorithm>
#include <array>

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

// Adds the spans [first, last), sorted by their first column, to the current row of `out`, those
// that overlap or touch joined into one.
void add_joined(const Span* first, const Span* last, RunMask& out) {
  if (first == last) return;
  Span cur = *first;
  for (const Span* s = first + 1; s != last; ++s) {
    if (s->a <= cur.b + 1) {
      cur.b = std::max(cur.b, s->b);
      continue;
    }
    out.add(cur.a, cur.b);
    cur = *s;
  }
  out.add(cur.a, cur.b);
}

constexpr int kMaxDirect = 15;           // rows joined without the general merge: radius 7 at most
constexpr int kMaxSingleSpanRadius = 5;  // the detector's options allow no more
static_assert(2 * kMaxSingleSpanRadius + 1 <= kMaxDirect);

// Up to kMaxDirect spans (one from each of 2r + 1 rows), kept sorted by their first column as
// they come (insertion: a handful), then added to a row joined where they touch.
class SortedSpans {
 public:
  void insert(const Span& s) {
    int k = n_++;
    for (; k > 0 && spans_[k - 1].a > s.a; --k) spans_[k] = spans_[k - 1];
    spans_[k] = s;
  }
  void add_joined_to(RunMask& out) const { add_joined(spans_.data(), spans_.data() + n_, out); }

 private:
  std::array<Span, kMaxDirect> spans_;
  int n_ = 0;
};

// Rows y0..y1 (inclusive) hold at most one span each; `empty` is set when one holds none.
bool single_spans(const RunMask& in, int y0, int y1, bool& empty) {
  empty = false;
  for (int j = y0; j <= y1; ++j) {
    const auto n = in.row_end(j) - in.row_begin(j);
    if (n > 1) return false;
    empty |= n == 0;
  }
  return true;
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
    // The common case, a convex blob (and the empty rows of its margin): at most one span in each
    // of the 2r + 1 rows, joined directly.
    bool empty = false;
    if (2 * r + 1 <= kMaxDirect && single_spans(in, y - r, y + r, empty)) {
      if (erode) {
        if (empty) continue;
        int a = in.row_begin(y - r)->a, b = in.row_begin(y - r)->b;
        for (int j = y - r + 1; j <= y + r; ++j)
          a = std::max(a, in.row_begin(j)->a), b = std::min(b, in.row_begin(j)->b);
        if (a <= b) out.add(a, b);
        continue;
      }
      SortedSpans sorted;
      for (int j = y - r; j <= y + r; ++j)
        if (in.row_begin(j) != in.row_end(j)) sorted.insert(*in.row_begin(j));
      sorted.add_joined_to(out);
      continue;
    }
    x.assign(in.row_begin(y - r), in.row_end(y - r));
    if (erode) {
      for (int j = y - r + 1; j <= y + r && !x.empty(); ++j)
        intersect(x, in.row_begin(j), in.row_end(j), tmp);
    } else {
      for (int j = y - r + 1; j <= y + r; ++j) x.insert(x.end(), in.row_begin(j), in.row_end(j));
      std::sort(x.begin(), x.end(), [](const Span& s, const Span& t) { return s.a < t.a; });
    }
    add_joined(x.data(), x.data() + x.size(), out);  // only a union has spans to join
  }
  out.end_rows();
}

}  // namespace

bool RunOpening::open_single_spans(const RunMask& in, int r, RunMask& out) {
  const int w = in.width(), h = in.height();
  // Erosion along rows: each span shrunk by r at both ends. A lamp's fringe (spans of 2r pixels
  // or fewer beside it, gaps near its ends) is gone after it; a row left with two spans is not
  // taken here.
  eroded_rows_.assign(static_cast<std::size_t>(h), Span{1, 0});
  for (int y = 0; y < h; ++y) {
    for (const Span* s = in.row_begin(y); s != in.row_end(y); ++s) {
      if (s->b - s->a < 2 * r) continue;
      if (eroded_rows_[y].a <= eroded_rows_[y].b) return false;
      eroded_rows_[y] = {s->a + r, s->b - r};
    }
  }
  // Along columns: row y's span is the intersection of rows y - r .. y + r (empty as soon as one
  // is), for y in [r, h - r); then grown by r along the row, kept off the r pixels at either end.
  // An eroded span lies in [r, w - 1 - r], so growing and clipping it cannot empty it.
  grown_.assign(static_cast<std::size_t>(h), Span{1, 0});
  for (int y = r; y < h - r; ++y) {
    int a = 0, b = w - 1;
    for (int j = y - r; j <= y + r && a <= b; ++j) {
      a = std::max(a, eroded_rows_[j].a);
      b = std::min(b, eroded_rows_[j].b);
    }
    if (a <= b) grown_[y] = {std::max(a - r, r), std::min(b + r, w - 1 - r)};
  }
  // Dilation along columns: row y is the union of the grown spans of rows y - r .. y + r. When
  // every two of them overlap or touch (the usual case: a lamp's rows), it is one span from the
  // least start to the greatest end; otherwise they are sorted and joined.
  out.reset(w, h);
  for (int y = 0; y < h; ++y) {
    out.begin_row();
    if (y < r || y >= h - r) continue;
    int n = 0, lo = w, hi = -1, last_start = -1, first_end = w;
    for (int j = y - r; j <= y + r; ++j) {
      const Span s = grown_[j];
      if (s.a > s.b) continue;
      ++n;
      lo = std::min(lo, s.a), hi = std::max(hi, s.b);
      last_start = std::max(last_start, s.a), first_end = std::min(first_end, s.b);
    }
    if (n == 0) continue;
    if (last_start <= first_end + 1) {
      out.add(lo, hi);
      continue;
    }
    SortedSpans sorted;
    for (int j = y - r; j <= y + r; ++j)
      if (grown_[j].a <= grown_[j].b) sorted.insert(grown_[j]);
    sorted.add_joined_to(out);
  }
  out.end_rows();
  return true;
}

void RunOpening::open(const RunMask& in, int r, RunMask& out) {
  if (r <= kMaxSingleSpanRadius && open_single_spans(in, r, out)) return;
  along_rows(in, r, true, rows_);
  along_columns(rows_, r, true, eroded_, a_, b_);
  along_rows(eroded_, r, false, dilated_rows_);
  along_columns(dilated_rows_, r, false, out, a_, b_);
}

}  // namespace lampnav::vision::detail
