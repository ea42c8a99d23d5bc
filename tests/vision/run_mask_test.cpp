// The lamp detector's opening on runs (vision/src/run_mask.hpp, white-box), against the opening
// written pixel by pixel from its definition: erosion then dilation by a (2r+1)^2 square, pixels
// within r of the mask's edge outside. Random masks of every density and size, r = 1 to 3.

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "run_mask.hpp"

namespace lampnav::vision::detail {
namespace {

using Bytes = std::vector<std::uint8_t>;

// One pass of the definition along rows (dx) or columns (dy): AND or OR over the 2r+1 pixels
// around, for pixels whose window lies inside; 0 elsewhere.
Bytes pass(const Bytes& in, int w, int h, int r, bool erode, bool rows) {
  Bytes out(in.size(), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int at = rows ? x : y, n = rows ? w : h;
      if (at < r || at >= n - r) continue;
      bool all = true, any = false;
      for (int j = -r; j <= r; ++j) {
        const bool set = rows ? in[static_cast<std::size_t>(y) * w + x + j]
                              : in[static_cast<std::size_t>(y + j) * w + x];
        all &= set;
        any |= set;
      }
      out[static_cast<std::size_t>(y) * w + x] = (erode ? all : any) ? 1 : 0;
    }
  }
  return out;
}

Bytes opened_by_definition(const Bytes& in, int w, int h, int r) {
  const Bytes eroded = pass(pass(in, w, h, r, true, true), w, h, r, true, false);
  return pass(pass(eroded, w, h, r, false, true), w, h, r, false, false);
}

RunMask runs_of(const Bytes& m, int w, int h) {
  RunMask out;
  out.reset(w, h);
  for (int y = 0; y < h; ++y) {
    out.begin_row();
    for (int x = 0; x < w;) {
      if (!m[static_cast<std::size_t>(y) * w + x]) {
        ++x;
        continue;
      }
      const int a = x;
      while (x < w && m[static_cast<std::size_t>(y) * w + x]) ++x;
      out.add(a, x - 1);
    }
  }
  out.end_rows();
  return out;
}

Bytes bytes_of(const RunMask& m) {
  Bytes out(static_cast<std::size_t>(m.width()) * m.height(), 0);
  for (int y = 0; y < m.height(); ++y) {
    int last = -2;
    for (const Span* s = m.row_begin(y); s != m.row_end(y); ++s) {
      EXPECT_LE(s->a, s->b) << "row " << y;
      EXPECT_GT(s->a, last + 1) << "row " << y << ": spans not sorted, apart and joined";
      last = s->b;
      for (int x = s->a; x <= s->b; ++x) out[static_cast<std::size_t>(y) * m.width() + x] = 1;
    }
  }
  return out;
}

TEST(RunOpening, SamePixelsAsTheOpeningByDefinition) {
  std::mt19937 rng(7);
  RunOpening opening;  // one, so that its scratch is reused from case to case
  RunMask out;
  int cases = 0, changed = 0;
  for (int r = 1; r <= 3; ++r) {
    for (const double density : {0.1, 0.5, 0.8, 0.95, 1.0}) {
      for (int trial = 0; trial < 12; ++trial) {
        const int w = 1 + static_cast<int>(rng() % 40), h = 1 + static_cast<int>(rng() % 30);
        // Blocks of random size, so that runs and holes of every length occur.
        Bytes m(static_cast<std::size_t>(w) * h, 0);
        std::bernoulli_distribution on(density);
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w;) {
            const int len = 1 + static_cast<int>(rng() % 6);
            const std::uint8_t v = on(rng) ? 1 : 0;
            for (int k = 0; k < len && x < w; ++k, ++x) m[static_cast<std::size_t>(y) * w + x] = v;
          }
        const Bytes expected = opened_by_definition(m, w, h, r);
        opening.open(runs_of(m, w, h), r, out);
        ASSERT_EQ(out.width(), w);
        ASSERT_EQ(out.height(), h);
        ASSERT_EQ(bytes_of(out), expected) << "r " << r << ", " << w << " x " << h;
        ++cases;
        changed += expected != m ? 1 : 0;
      }
    }
  }
  EXPECT_EQ(cases, 180);
  EXPECT_GT(changed, 150);  // the opening did something in most cases
}

// Lamp-like masks: one ragged span per row (a slanted bar, its ends rough), some rows with a
// fringe beside it or a gap in it, some rows empty. Most windows of 2r+1 rows then hold one span
// a row, which the opening joins directly; r up to 5, the options' largest.
TEST(RunOpening, SamePixelsAsTheDefinitionOnLampLikeMasks) {
  std::mt19937 rng(11);
  RunOpening opening;
  RunMask out;
  int cases = 0, single_rows = 0, rows = 0;
  for (int r = 1; r <= 5; ++r) {
    for (int trial = 0; trial < 30; ++trial) {
      const int w = 20 + static_cast<int>(rng() % 60), h = 10 + static_cast<int>(rng() % 40);
      Bytes m(static_cast<std::size_t>(w) * h, 0);
      const double slope = (static_cast<int>(rng() % 200) - 100) / 100.0;
      const int half = 3 + static_cast<int>(rng() % (w / 3));
      for (int y = 1; y < h - 1; ++y) {
        if (rng() % 20 == 0) continue;  // an empty row
        const int mid = w / 2 + static_cast<int>(slope * (y - h / 2));
        const int a = std::max(0, mid - half + static_cast<int>(rng() % 3) - 1);
        const int b = std::min(w - 1, mid + half + static_cast<int>(rng() % 3) - 1);
        for (int x = a; x <= b; ++x) m[static_cast<std::size_t>(y) * w + x] = 1;
        if (rng() % 10 == 0 && b + 3 < w) m[static_cast<std::size_t>(y) * w + b + 2] = 1;
        if (rng() % 10 == 0 && b - a > 4) m[static_cast<std::size_t>(y) * w + (a + b) / 2] = 0;
      }
      const RunMask in = runs_of(m, w, h);
      for (int y = 0; y < h; ++y) {
        ++rows;
        single_rows += in.row_end(y) - in.row_begin(y) == 1 ? 1 : 0;
      }
      opening.open(in, r, out);
      ASSERT_EQ(bytes_of(out), opened_by_definition(m, w, h, r))
          << "r " << r << ", " << w << " x " << h << ", trial " << trial;
      ++cases;
    }
  }
  EXPECT_EQ(cases, 150);
  EXPECT_GT(single_rows, rows * 3 / 5);
}

// Masks of one span a row (or none), the lamp's usual mask, which the opening takes without
// intermediate masks: bars of every slope, and staircases of random steps, whose rows the
// dilation can split in two (two squares inside the mask that share rows but not columns).
TEST(RunOpening, SamePixelsAsTheDefinitionOnMasksOfOneSpanARow) {
  std::mt19937 rng(5);
  RunOpening opening;
  RunMask out;
  int cases = 0, split = 0;
  for (int r = 1; r <= 5; ++r) {
    for (int trial = 0; trial < 40; ++trial) {
      const bool stairs = trial % 2 == 0;
      const int w = (stairs ? 40 : 8) + static_cast<int>(rng() % 60);
      const int h = 3 + static_cast<int>(rng() % 40);
      Bytes m(static_cast<std::size_t>(w) * h, 0);
      const double slope = (static_cast<int>(rng() % 600) - 300) / 100.0;
      const int half = static_cast<int>(rng() % (w / 2 + 1));
      int a = 0, b = -1, step_left = 0, step = 0;
      const int side = 2 * r + 1 + static_cast<int>(rng() % 4), gap = 1 + trial % 3;
      for (int y = 0; y < h; ++y) {
        if (stairs && step_left-- <= 0) {
          // The next step: left, across, right, across, left...; a side step 2r + 1 to 2r + 4
          // wide and r + 1 to 2r + 1 high, 1 to 3 pixels apart, a step across r to 2r high (no
          // square fits in it).
          const int kind = step++ % 4;
          const bool across = kind % 2 == 1;
          step_left =
              across ? r + static_cast<int>(rng() % r) : r + static_cast<int>(rng() % (r + 1));
          a = kind == 2 ? 2 + side + gap : 2;
          b = std::min(w - 1, kind == 0 ? 1 + side : 1 + 2 * side + gap);
        } else if (!stairs) {
          const int mid = w / 2 + static_cast<int>(slope * (y - h / 2));
          a = std::max(0, mid - half + static_cast<int>(rng() % 3) - 1);
          b = std::min(w - 1, mid + half + static_cast<int>(rng() % 3) - 1);
        }
        if (rng() % 15 == 0) continue;  // an empty row
        for (int x = a; x <= b; ++x) m[static_cast<std::size_t>(y) * w + x] = 1;
      }
      const RunMask in = runs_of(m, w, h);
      for (int y = 0; y < h; ++y) ASSERT_LE(in.row_end(y) - in.row_begin(y), 1);
      opening.open(in, r, out);
      ASSERT_EQ(bytes_of(out), opened_by_definition(m, w, h, r))
          << "r " << r << ", " << w << " x " << h << ", trial " << trial;
      for (int y = 0; y < h; ++y) split += out.row_end(y) - out.row_begin(y) > 1 ? 1 : 0;
      ++cases;
    }
  }
  EXPECT_EQ(cases, 200);
  EXPECT_GT(split, 100);  // rows the dilation split: the join's other outcome is tested too
}

}  // namespace
}  // namespace lampnav::vision::detail
