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
  grown_rows_.assign(static_cast<std::size_t>(h), Span{1, 0});
  for (int y = r; y < h - r; ++y) {
    int a = 0, b = w - 1;
    for (int j = y - r; j <= y + r && a <= b; ++j) {
      a = std::max(a, eroded_rows_[j].a);
      b = std::min(b, eroded_rows_[j].b);
    }
    if (a <= b) grown_rows_[y] = {std::max(a - r, r), std::min(b + r, w - 1 - r)};
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
      const Span s = grown_rows_[j];
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
      if (grown_rows_[j].a <= grown_rows_[j].b) sorted.insert(grown_rows_[j]);
    sorted.add_joined_to(out);
  }
  out.end_rows();
  return true;
}

void RunOpening::open_general(const RunMask& in, int r, RunMask& out) {
  const int w = in.width(), h = in.height();
  // Erosion along rows: each span shrunk by r at both ends. A lamp's fringe (spans of 2r pixels
  // or fewer beside it) is gone after it.
  eroded_.reset(w, h);
  for (int y = 0; y < h; ++y) {
    eroded_.begin_row();
    for (const Span* s = in.row_begin(y); s != in.row_end(y); ++s)
      if (s->b - s->a >= 2 * r) eroded_.add(s->a + r, s->b - r);
  }
  eroded_.end_rows();
  // Erosion along columns, then dilation along rows: row y in [r, h - r) is the intersection of
  // the eroded rows y - r .. y + r (empty as soon as one is), each of its spans grown by r and
  // kept off the r pixels at either end of the row, those that then touch joined. The usual case
  // (a lamp's rows, and its ragged first and last rows once eroded) is one span in each of those
  // rows: their intersection is from the greatest start to the least end. An eroded span lies in
  // [r, w - 1 - r], so growing and clipping it cannot empty it.
  grown_.reset(w, h);
  for (int y = 0; y < h; ++y) {
    grown_.begin_row();
    if (y < r || y >= h - r) continue;
    bool single = true, empty = false;
    for (int j = y - r; j <= y + r && !empty; ++j) {
      const auto n = eroded_.row_end(j) - eroded_.row_begin(j);
      empty = n == 0;
      single &= n == 1;
    }
    if (empty) continue;
    if (single) {
      int a = 0, b = w - 1;
      for (int j = y - r; j <= y + r; ++j)
        a = std::max(a, eroded_.row_begin(j)->a), b = std::min(b, eroded_.row_begin(j)->b);
      if (a <= b) grown_.add(std::max(a - r, r), std::min(b + r, w - 1 - r));
      continue;
    }
    a_.assign(eroded_.row_begin(y - r), eroded_.row_end(y - r));
    for (int j = y - r + 1; j <= y + r && !a_.empty(); ++j)
      intersect(a_, eroded_.row_begin(j), eroded_.row_end(j), b_);
    for (Span& s : a_) s = {std::max(s.a - r, r), std::min(s.b + r, w - 1 - r)};
    add_joined(a_.data(), a_.data() + a_.size(), grown_);
  }
  grown_.end_rows();
  // Dilation along columns: row y is the union of the grown rows y - r .. y + r. When each holds
  // at most one span and every two of them overlap or touch, it is one span from the least start
  // to the greatest end; otherwise they are sorted and joined.
  out.reset(w, h);
  for (int y = 0; y < h; ++y) {
    out.begin_row();
    if (y < r || y >= h - r) continue;
    int n = 0, lo = w, hi = -1, last_start = -1, first_end = w;
    bool single = true;
    for (int j = y - r; j <= y + r; ++j) {
      const Span *s = grown_.row_begin(j), *end = grown_.row_end(j);
      if (s == end) continue;
      single &= end - s == 1;
      ++n;
      lo = std::min(lo, s->a), hi = std::max(hi, s->b);
      last_start = std::max(last_start, s->a), first_end = std::min(first_end, s->b);
    }
    if (n == 0) continue;
    if (single && last_start <= first_end + 1) {
      out.add(lo, hi);
      continue;
    }
    a_.clear();
    for (int j = y - r; j <= y + r; ++j)
      a_.insert(a_.end(), grown_.row_begin(j), grown_.row_end(j));
    std::sort(a_.begin(), a_.end(), [](const Span& s, const Span& t) { return s.a < t.a; });
    add_joined(a_.data(), a_.data() + a_.size(), out);
  }
  out.end_rows();
}

void RunOpening::open(const RunMask& in, int r, RunMask& out) {
  if (r <= kMaxSingleSpanRadius && open_single_spans(in, r, out)) return;
  open_general(in, r, out);
}

}  // namespace lampnav::vision::detail
