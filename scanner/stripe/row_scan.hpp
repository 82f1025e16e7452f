#pragma once

#include "scanner/stripe/stripe_image.hpp"

// The row scan of the stripe detector (internal): for each row of a stripe running down the
// image, its brightest pixel and whether it holds a second peak.
namespace uwscan::scanner::stripe_detail {

// What the scan found on one row.
struct RowFound {
  int u0 = 0;                // the brightest pixel (the first of equal maxima)
  int top = 0;               // its value
  bool second_peak = false;  // a local maximum farther than the separation from u0 reaches the cut
};

// Scans rows [begin, end) of `image` into found[v - begin]. The second-peak test runs when
// ratio < 1 on a row whose top reaches `threshold`: a local maximum (brighter than the pixel
// before, at least as bright as the one after) more than `separation` pixels from u0 that
// reaches SecondPeakCut(top, threshold, ratio). Compiled for AVX2 too, chosen at run time.
void ScanRows(const StripeImage& image, int begin, int end, int separation, int threshold,
              double ratio, RowFound* found);

}  // namespace uwscan::scanner::stripe_detail
