#include "map_drawing.hpp"

#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "lampnav/core/error.hpp"

namespace lampnav::apps {

using Eigen::Vector2d;
using graph::Place;

namespace {

struct Rgb {
  double r, g, b;
};

Rgb place_colour(Place p) {
  switch (p) {
    case Place::corridor:
      return {0.80, 0.87, 0.95};
    case Place::junction:
      return {0.62, 0.76, 0.92};
    case Place::corner:
      return {0.70, 0.82, 0.70};
    case Place::end:
      return {0.88, 0.80, 0.92};
    case Place::door:
      return {0.85, 0.62, 0.40};
    case Place::hall:
      return {0.93, 0.90, 0.78};
    case Place::room:
      return {0.92, 0.92, 0.92};
    case Place::waypoint:
      return {0.75, 0.75, 0.75};
  }
  return {1, 1, 1};
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == b;
         });
}

// Map metres to picture pixels: x right, y up in the map becomes y down in the picture.
struct View {
  double scale = 1, x0 = 0, y1 = 0, margin = 0;
  double px(double x) const { return margin + (x - x0) * scale; }
  double py(double y) const { return margin + (y1 - y) * scale; }
};

void text_centered(cairo_t* cr, const std::string& s, double x, double y) {
  cairo_text_extents_t ext;
  cairo_text_extents(cr, s.c_str(), &ext);
  cairo_move_to(cr, x - ext.width / 2 - ext.x_bearing, y - ext.height / 2 - ext.y_bearing);
  cairo_show_text(cr, s.c_str());
}

void draw(cairo_t* cr, const graph::TopologicalMap& map, const View& v, const DrawingOptions& o,
          double width_px, double height_px) {
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

  // Regions.
  for (const auto& n : map.nodes()) {
    const auto& vs = n.region.vertices();
    cairo_new_path(cr);
    for (std::size_t i = 0; i < vs.size(); ++i) {
      (i == 0 ? cairo_move_to : cairo_line_to)(cr, v.px(vs[i].x()), v.py(vs[i].y()));
    }
    cairo_close_path(cr);
    const Rgb c = place_colour(n.place);
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.45, 0.45, 0.5);
    cairo_set_line_width(cr, 1.0);
    cairo_stroke(cr);
  }
  // Corridor axes, dashed.
  const double dash[] = {6.0, 4.0};
  cairo_set_dash(cr, dash, 2, 0);
  cairo_set_source_rgb(cr, 0.55, 0.62, 0.75);
  for (const auto& n : map.nodes()) {
    if (!n.axis) continue;
    cairo_move_to(cr, v.px(n.axis->first.x()), v.py(n.axis->first.y()));
    cairo_line_to(cr, v.px(n.axis->second.x()), v.py(n.axis->second.y()));
    cairo_stroke(cr);
  }
  cairo_set_dash(cr, nullptr, 0, 0);
  // Doors along corridors: a thick mark on the wall at `at`, on `side`.
  for (const auto& n : map.nodes()) {
    if (!n.axis) continue;
    const Vector2d dir = n.axis->direction();
    const Vector2d left(-dir.y(), dir.x());
    const double half_width = n.width.value_or(2.0) / 2;
    for (const auto& d : n.doors) {
      const Vector2d c =
          n.axis->point_at(d.at) + (d.side == graph::Side::left ? 1 : -1) * half_width * left;
      const Vector2d a = c - 0.45 * dir, b = c + 0.45 * dir;
      cairo_set_source_rgb(cr, 0.55, 0.30, 0.10);
      cairo_set_line_width(cr, std::max(3.0, 0.15 * v.scale));
      cairo_move_to(cr, v.px(a.x()), v.py(a.y()));
      cairo_line_to(cr, v.px(b.x()), v.py(b.y()));
      cairo_stroke(cr);
    }
  }
  // Graph edges between node points, then the nodes.
  cairo_set_source_rgba(cr, 0.15, 0.15, 0.15, 0.6);
  cairo_set_line_width(cr, 1.5);
  for (const auto& e : map.edges()) {
    for (const auto& line : e.geometry) {
      for (std::size_t i = 0; i < line.size(); ++i) {
        (i == 0 ? cairo_move_to : cairo_line_to)(cr, v.px(line[i].x()), v.py(line[i].y()));
      }
      cairo_stroke(cr);
    }
  }
  for (const auto& n : map.nodes()) {
    cairo_new_path(cr);
    cairo_arc(cr, v.px(n.point.x()), v.py(n.point.y()), 3.5, 0, 2 * M_PI);
    cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
    cairo_fill(cr);
  }
  // Lamps at their true size (at least a few pixels).
  for (const auto& n : map.nodes()) {
    for (const auto& l : n.lamps) {
      cairo_new_path(cr);  // text leaves a current point that would join the shapes
      cairo_save(cr);
      cairo_translate(cr, v.px(l.xyz.x()), v.py(l.xyz.y()));
      cairo_rotate(cr, -l.yaw);  // picture y points down
      const double len = std::max(4.0, l.length * v.scale), wid = std::max(3.0, l.width * v.scale);
      if (l.shape == graph::LampShape::disc) {
        cairo_arc(cr, 0, 0, len / 2, 0, 2 * M_PI);
      } else {
        cairo_rectangle(cr, -len / 2, -wid / 2, len, wid);
      }
      cairo_set_source_rgb(cr, 1.0, 0.84, 0.15);
      cairo_fill_preserve(cr);
      cairo_set_source_rgb(cr, 0.55, 0.42, 0.0);
      cairo_set_line_width(cr, 1.0);
      cairo_stroke(cr);
      cairo_restore(cr);
      if (o.lamp_ids) {
        cairo_set_font_size(cr, 9);
        cairo_set_source_rgb(cr, 0.4, 0.3, 0.0);
        text_centered(cr, l.id.value, v.px(l.xyz.x()), v.py(l.xyz.y()) - std::max(8.0, wid));
      }
    }
  }
  // Names at the region centroids.
  cairo_set_font_size(cr, 12);
  cairo_set_source_rgb(cr, 0.05, 0.05, 0.2);
  for (const auto& n : map.nodes()) {
    const Vector2d c = n.region.size() >= 3 ? n.region.centroid() : n.point;
    text_centered(cr, n.name, v.px(c.x()), v.py(c.y()) + (n.axis ? 12 : -8));
  }
  // Title, legend and a scale bar along the bottom.
  cairo_set_font_size(cr, 14);
  cairo_set_source_rgb(cr, 0, 0, 0);
  const std::string title = (map.name().empty() ? std::string("map") : map.name()) + ": " +
                            std::to_string(map.node_count()) + " nodes, " +
                            std::to_string(map.edge_count()) + " edges, " +
                            std::to_string(map.lamp_count()) + " lamps";
  cairo_move_to(cr, 10, 20);
  cairo_show_text(cr, title.c_str());
  double lx = 10;
  const double ly = height_px - 16;
  cairo_set_font_size(cr, 11);
  for (Place p : {Place::corridor, Place::junction, Place::corner, Place::end, Place::door,
                  Place::hall, Place::room}) {
    const Rgb c = place_colour(p);
    cairo_rectangle(cr, lx, ly - 9, 12, 12);
    cairo_set_source_rgb(cr, c.r, c.g, c.b);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.4, 0.4, 0.4);
    cairo_stroke(cr);
    cairo_move_to(cr, lx + 16, ly + 1);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_show_text(cr, graph::to_string(p));
    lx += 85;
  }
  // Scale bar: the longest 1, 2 or 5 times a power of ten that fits a fifth of the width.
  const double room_m = width_px / 5 / v.scale;
  const double decade = std::pow(10.0, std::floor(std::log10(room_m)));
  const double bar_m = room_m >= 5 * decade   ? 5 * decade
                       : room_m >= 2 * decade ? 2 * decade
                                              : decade;
  const double bar_px = bar_m * v.scale;
  cairo_set_line_width(cr, 3);
  cairo_new_path(cr);
  cairo_move_to(cr, width_px - 20 - bar_px, ly);
  cairo_line_to(cr, width_px - 20, ly);
  cairo_stroke(cr);
  char label[32];
  std::snprintf(label, sizeof label, "%g m", bar_m);
  text_centered(cr, label, width_px - 20 - bar_px / 2, ly - 10);
}

}  // namespace

void draw_map(const graph::TopologicalMap& map, const std::string& path,
              const DrawingOptions& options) {
  const bool png = ends_with(path, ".png");
  const bool svg = ends_with(path, ".svg");
  if (!png && !svg) throw InputError({path, "", ""}, "unknown picture format (use .png or .svg)");
  if (map.node_count() == 0) throw InputError({path, "", ""}, "the map has no nodes to draw");

  // Everything drawn: regions, node points (a Nav2 graph's waypoints have no region) and edges.
  graph::Box2 box{map.node_at_index(0).point, map.node_at_index(0).point};
  auto cover = [&box](const Vector2d& p) {
    box.min = box.min.cwiseMin(p);
    box.max = box.max.cwiseMax(p);
  };
  for (const auto& n : map.nodes()) {
    cover(n.point);
    for (const auto& p : n.region.vertices()) cover(p);
  }
  for (const auto& e : map.edges()) {
    for (const auto& line : e.geometry) {
      for (const auto& p : line) cover(p);
    }
  }
  const Vector2d size = (box.max - box.min).cwiseMax(Vector2d(1e-3, 1e-3));
  View v;
  v.margin = 40;
  v.scale = (options.max_size_px - 2 * v.margin) / std::max(size.x(), size.y());
  v.x0 = box.min.x();
  v.y1 = box.max.y();
  const double w = std::ceil(size.x() * v.scale + 2 * v.margin);
  const double h = std::ceil(size.y() * v.scale + 2 * v.margin + 30);  // room for the legend

  cairo_surface_t* surface =
      png ? cairo_image_surface_create(CAIRO_FORMAT_ARGB32, static_cast<int>(w),
                                       static_cast<int>(h))
          : cairo_svg_surface_create(path.c_str(), w, h);
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> guard(surface,
                                                                           cairo_surface_destroy);
  if (cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS) {
    throw InputError({path, "", ""}, std::string("cannot create the picture: ") +
                                         cairo_status_to_string(cairo_surface_status(surface)));
  }
  cairo_t* cr = cairo_create(surface);
  draw(cr, map, v, options, w, h);
  const cairo_status_t st = cairo_status(cr);
  cairo_destroy(cr);
  if (st != CAIRO_STATUS_SUCCESS) {
    throw InputError({path, "", ""}, std::string("drawing failed: ") + cairo_status_to_string(st));
  }
  cairo_surface_flush(surface);
  if (png) {
    const cairo_status_t ws = cairo_surface_write_to_png(surface, path.c_str());
    if (ws != CAIRO_STATUS_SUCCESS) {
      throw InputError({path, "", ""}, std::string("cannot write: ") + cairo_status_to_string(ws));
    }
  } else {
    cairo_surface_finish(surface);
    if (cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS) {
      throw InputError({path, "", ""}, std::string("cannot write: ") +
                                           cairo_status_to_string(cairo_surface_status(surface)));
    }
  }
}

}  // namespace lampnav::apps
