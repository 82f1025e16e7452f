#include "scanner/optics/ray.hpp"

namespace uwscan::scanner {

const char* ToString(HitStatus status) {
  switch (status) {
    case HitStatus::kHit:
      return "hit";
    case HitStatus::kParallel:
      return "parallel";
    case HitStatus::kBehind:
      return "behind";
    case HitStatus::kOutsideSurface:
      return "outside_surface";
    case HitStatus::kNoIntersection:
      return "no_intersection";
    case HitStatus::kTotalInternalReflection:
      return "total_internal_reflection";
  }
  return "unknown";
}

}  // namespace uwscan::scanner
