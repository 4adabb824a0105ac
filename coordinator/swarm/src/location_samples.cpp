// Location sampling of SCHEDULE_SINGLE (seed 002 Anhang A.1, lines 2-3 and 15-28, §6).
#include <algorithm>
#include <deque>

#include "boost_geometry.hpp"

#include "scheduler_state.hpp"

namespace oscar::swarm {

namespace bg = boost::geometry;

namespace {

using Area = bg::model::multi_polygon<Polygon>;
using Box = bg::model::box<Point>;
using Line = bg::model::linestring<Point>;

constexpr double kMinPieceArea = 1e-12;  // m²: smaller pieces are rounding residue

// SAMPLE_LOCATION: a line x = x* through the centroid of the area's largest piece, cut with that
// piece; the middle of the longest cut. The centroid (not the middle of the extent) keeps an L's
// samples spread over both legs. Deterministic, so a problem plans the same every time.
std::optional<Point> sample_location(const Area& area) {
  const auto largest = std::max_element(area.begin(), area.end(), [](const auto& a, const auto& b) {
    return bg::area(a) < bg::area(b);
  });
  const Box box = bg::return_envelope<Box>(*largest);
  Point centroid(0, 0);
  bg::centroid(*largest, centroid);
  const double x = centroid.x();
  const Line line{{x, box.min_corner().y() - 1}, {x, box.max_corner().y() + 1}};
  bg::model::multi_linestring<Line> cuts;
  bg::intersection(line, *largest, cuts);
  const Line* longest = nullptr;
  for (const auto& c : cuts) {
    if (!longest || bg::length(c) > bg::length(*longest)) longest = &c;
  }
  if (!longest || longest->size() < 2) return std::nullopt;
  const Point a = longest->front(), b = longest->back();
  const Point p((a.x() + b.x()) / 2, (a.y() + b.y()) / 2);
  if (!bg::within(p, *largest)) return std::nullopt;  // the cut ran along an edge
  return p;
}

// DEVIDE_AREA: the area's bounding box split at the sample into four rectangles, each cut with the
// area; empty pieces are dropped.
std::vector<Area> divide_area(const Area& area, const Point& at) {
  const Box box = bg::return_envelope<Box>(area);
  const Point lo = box.min_corner(), hi = box.max_corner();
  const std::vector<Box> quarters{Box(lo, at), Box({at.x(), lo.y()}, {hi.x(), at.y()}),
                                  Box({lo.x(), at.y()}, {at.x(), hi.y()}), Box(at, hi)};
  std::vector<Area> pieces;
  for (const auto& q : quarters) {
    Area piece;
    bg::intersection(area, q, piece);
    if (bg::area(piece) > kMinPieceArea) pieces.push_back(std::move(piece));
  }
  return pieces;
}

}  // namespace

std::vector<Point> sample_locations(const Polygon& area, const std::vector<Polygon>& obstacles,
                                    int count) {
  // Line 2: the location space is the area minus the static obstacles.
  Area space{area};
  for (const auto& o : obstacles) {
    Area rest;
    bg::difference(space, o, rest);
    space = std::move(rest);
  }
  // Lines 15-28: breadth first over ever smaller rectangles, so the samples spread over the space.
  std::vector<Point> locations;
  std::deque<Area> queue;
  if (bg::area(space) > kMinPieceArea) queue.push_back(std::move(space));
  for (int i = count; !queue.empty() && i > 0; --i) {
    const Area piece = std::move(queue.front());
    queue.pop_front();
    const auto p = sample_location(piece);
    if (!p) continue;
    locations.push_back(*p);
    for (auto& sub : divide_area(piece, *p)) queue.push_back(std::move(sub));
  }
  return locations;
}

}  // namespace oscar::swarm
