#pragma once
// A binary mask kept as runs of set pixels per row, and its morphological opening done on the
// runs: the cost follows a mask's outline, not its area. Internal to vision (the lamp detector).

#include <vector>

namespace lampnav::vision::detail {

// Columns a..b (inclusive) of a row.
struct Span {
  int a = 0, b = 0;
};

// A width x height mask: row y's spans, sorted and disjoint, are spans[start[y] .. start[y+1]).
class RunMask {
 public:
  void reset(int width, int height);  // no rows yet
  // Rows are added in order, 0 first.
  void begin_row() { start_.push_back(static_cast<int>(spans_.size())); }
  void add(int a, int b) { spans_.push_back({a, b}); }
  void end_rows() { start_.push_back(static_cast<int>(spans_.size())); }
  // The spans of row y: [first, last).
  const Span* row_begin(int y) const { return spans_.data() + start_[y]; }
  const Span* row_end(int y) const { return spans_.data() + start_[y + 1]; }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<Span> spans_;
  std::vector<int> start_;
};

// Opening (erosion, then dilation) by a (2r+1)^2 square, separably (erosion along rows, then
// columns; dilation along rows, then columns), with the pixels within r of the mask's own edge
// counted as outside (the caller pads the mask by more than r). The same pixels as the byte-wise
// opening; scratch kept from call to call.
class RunOpening {
 public:
  void open(const RunMask& in, int r, RunMask& out);

 private:
  // A mask left with at most one span in every row by the erosion along rows (a lamp, with or
  // without a fringe): the erosion along columns and the dilation are then done on two ints a
  // row, without intermediate masks. False, `out` untouched, for any other mask.
  bool open_single_spans(const RunMask& in, int r, RunMask& out);
  // Any mask (a lamp's ragged first or last row leaves several spans after the erosion along
  // rows), in three passes over the rows.
  void open_general(const RunMask& in, int r, RunMask& out);
  RunMask eroded_, grown_;  // open_general: eroded along rows; then along columns, grown along rows
  std::vector<Span> a_, b_;
  std::vector<Span> eroded_rows_, grown_rows_;  // open_single_spans: a span a row, a > b when none
};

}  // namespace lampnav::vision::detail
