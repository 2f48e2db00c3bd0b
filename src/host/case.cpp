// Case file reading and validation (docs/case-file.md).
//
// The TOML text is parsed with toml++, the --set overrides are applied to the parsed tree, and
// the tree is then walked by small `Reader`s, one per table, that know the table's dotted key
// path ("body['slab'].shape") and report every problem as an InputError naming file, line and
// key. Entries of arrays of tables are named by their `name` when they have one
// (material['steel'], body['slab']) and by their index otherwise (load[0], body['slab'].cut[1]).
// Values that came from --set report the source "--set" instead of a file line.
#include "host/case.hpp"
#include "host/mesh.hpp"  // shape_bounds

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string_view>
#include <unordered_set>
#include <utility>

namespace fracta {

namespace {

std::string format_error(const std::string& file, int line, const std::string& key,
                         const std::string& what) {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  s += ": ";
  if (!key.empty()) s += key + ": ";
  return s + what;
}

}  // namespace

InputError::InputError(const std::string& file_, int line_, const std::string& key_,
                       const std::string& what)
    : std::runtime_error(format_error(file_, line_, key_, what)),
      file(file_),
      line(line_),
      key(key_) {}

namespace {

using KeyList = std::vector<std::string_view>;
template <class E>
using Choices = std::vector<std::pair<std::string_view, E>>;

constexpr double kPi = 3.14159265358979323846;
const char* const kOverrideSource = "--set";

// ---------------------------------------------------------------------------------------------
// Small text helpers

std::string fmt(double v) {
  std::ostringstream o;
  o << std::setprecision(10) << v;
  return o.str();
}

std::string in_quotes(std::string_view s) {
  return "'" + std::string(s) + "'";
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// Optimal-string-alignment distance (Levenshtein plus adjacent transpositions).
size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

// "; did you mean 'X'?" when a candidate matches case-insensitively or is within distance 2.
std::string did_you_mean(std::string_view word, const std::vector<std::string_view>& candidates) {
  std::string_view best;
  size_t best_distance = 3;
  for (std::string_view c : candidates) {
    size_t dist = lower(c) == lower(word) ? 0 : edit_distance(word, c);
    if (dist < best_distance) {
      best = c;
      best_distance = dist;
    }
  }
  return best_distance <= 2 ? "; did you mean " + in_quotes(best) + "?" : "";
}

std::string join(const std::vector<std::string_view>& words, std::string_view sep) {
  std::string out;
  for (size_t i = 0; i < words.size(); ++i)
    out += (i ? std::string(sep) : "") + std::string(words[i]);
  return out;
}

template <class E>
std::vector<std::string_view> names_of(const Choices<E>& choices) {
  std::vector<std::string_view> out;
  for (const auto& c : choices) out.push_back(c.first);
  return out;
}

template <class E>
const char* name_of(const Choices<E>& choices, E value) {
  for (const auto& c : choices)
    if (c.second == value) return c.first.data();
  return "?";
}

// The choice tables double as the to_string() tables (string literals, so data() is terminated).
const Choices<Formulation> kFormulations = {{"plane_strain", Formulation::plane_strain},
                                            {"plane_stress", Formulation::plane_stress},
                                            {"axisymmetric", Formulation::axisymmetric}};
const Choices<MaterialModel> kModels = {{"elastic", MaterialModel::elastic},
                                        {"bilinear_j2", MaterialModel::bilinear_j2},
                                        {"mohr_coulomb", MaterialModel::mohr_coulomb},
                                        {"hjc", MaterialModel::hjc},
                                        {"johnson_cook", MaterialModel::johnson_cook}};
const Choices<BodyMethod> kMethods = {{"fe", BodyMethod::fe},
                                      {"de", BodyMethod::de},
                                      {"adaptive", BodyMethod::adaptive},
                                      {"rigid", BodyMethod::rigid}};
const Choices<HourglassForm> kHourglass = {{"viscous", HourglassForm::viscous},
                                           {"stiffness", HourglassForm::stiffness}};
const Choices<bool> kPrecisions = {{"single", true}, {"double", false}};
const Choices<Integration> kIntegration = {{"reduced", Integration::reduced},
                                           {"full", Integration::full}};
const Choices<Shape::Type> kShapeTypes = {{"rectangle", Shape::Type::rectangle},
                                          {"circle", Shape::Type::circle},
                                          {"semicircle", Shape::Type::semicircle},
                                          {"polygon", Shape::Type::polygon}};
const Choices<Load::Type> kLoadTypes = {{"pressure", Load::Type::pressure},
                                        {"force", Load::Type::force},
                                        {"traction", Load::Type::traction}};
const Choices<Boundary::Type> kBoundaryTypes = {
    {"fixed_x", Boundary::Type::fixed_x}, {"fixed_y", Boundary::Type::fixed_y},
    {"fixed", Boundary::Type::fixed},     {"velocity", Boundary::Type::velocity},
    {"support", Boundary::Type::support}, {"bar", Boundary::Type::bar}};
const std::vector<std::string_view> kOutputFields = {
    "velocity", "displacement", "stress", "plastic_strain", "pressure", "von_mises", "damage"};

const char* type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    default:
      return "nothing";
  }
}

// ---------------------------------------------------------------------------------------------
// Where nodes come from: the case file, or a --set override.

class Source {
 public:
  explicit Source(std::string file) : file_(std::move(file)) {}

  // Marks a node (and everything inside it) as coming from --set.
  void mark_override(const toml::node& n) {
    overridden_.insert(&n);
    if (const toml::table* t = n.as_table()) {
      for (auto&& kv : *t) mark_override(kv.second);
    } else if (const toml::array* a = n.as_array()) {
      for (const toml::node& e : *a) mark_override(e);
    }
  }

  SourcePos pos(const toml::node& n) const {
    if (overridden_.count(&n)) return {kOverrideSource, 0, 0};
    return {file_, static_cast<int>(n.source().begin.line),
            static_cast<int>(n.source().begin.column)};
  }

  [[noreturn]] void fail(const toml::node& n, const std::string& key,
                         const std::string& msg) const {
    SourcePos p = pos(n);
    throw InputError(p.file, p.line, key, msg);
  }

 private:
  std::string file_;
  std::unordered_set<const toml::node*> overridden_;
};

// ---------------------------------------------------------------------------------------------
// Value conversion with checks, one node at a time.

// An interval such as (0, 1] or [0, inf); violation() describes the first bound broken.
struct Range {
  std::optional<double> lo, hi;
  bool lo_open = false, hi_open = false;

  static Range any() { return {}; }
  static Range gt(double v) { return Range{v, std::nullopt, true, false}; }
  static Range ge(double v) { return Range{v, std::nullopt, false, false}; }
  Range lt(double v) const { return Range{lo, v, lo_open, true}; }
  Range le(double v) const { return Range{lo, v, lo_open, false}; }

  std::string violation(double v) const {
    if (lo && (lo_open ? !(v > *lo) : !(v >= *lo)))
      return std::string("must be ") + (lo_open ? "> " : ">= ") + fmt(*lo) + " (got " + fmt(v) +
             ")";
    if (hi && (hi_open ? !(v < *hi) : !(v <= *hi)))
      return std::string("must be ") + (hi_open ? "< " : "<= ") + fmt(*hi) + " (got " + fmt(v) +
             ")";
    return "";
  }
};

double to_number(const Source& src, const toml::node& n, const std::string& key, Range range) {
  double v = 0;
  if (const auto* i = n.as_integer()) {
    v = static_cast<double>(i->get());
  } else if (const auto* f = n.as_floating_point()) {
    v = f->get();
  } else {
    src.fail(n, key, std::string("expected a number, got ") + type_name(n));
  }
  if (!std::isfinite(v)) src.fail(n, key, "must be a finite number (got " + fmt(v) + ")");
  std::string bad = range.violation(v);
  if (!bad.empty()) src.fail(n, key, bad);
  return v;
}

std::string to_string_value(const Source& src, const toml::node& n, const std::string& key) {
  if (const auto* s = n.as_string()) return s->get();
  src.fail(n, key, std::string("expected a string, got ") + type_name(n));
}

const toml::table& to_table(const Source& src, const toml::node& n, const std::string& key) {
  if (const auto* t = n.as_table()) return *t;
  src.fail(n, key, std::string("expected a table, got ") + type_name(n));
}

const toml::array& to_array(const Source& src, const toml::node& n, const std::string& key) {
  if (const auto* a = n.as_array()) return *a;
  src.fail(n, key, std::string("expected an array, got ") + type_name(n));
}

std::vector<double> to_numbers(const Source& src, const toml::node& n, const std::string& key) {
  const toml::array& a = to_array(src, n, key);
  std::vector<double> out;
  for (size_t i = 0; i < a.size(); ++i)
    out.push_back(to_number(src, a[i], key + "[" + std::to_string(i) + "]", Range::any()));
  return out;
}

Vec2 to_vec2(const Source& src, const toml::node& n, const std::string& key) {
  const toml::array& a = to_array(src, n, key);
  if (a.size() != 2)
    src.fail(n, key,
             "expected [x, y] (2 numbers), got " + std::to_string(a.size()) +
                 (a.size() == 1 ? " value" : " values"));
  std::vector<double> v = to_numbers(src, n, key);
  return {v[0], v[1]};
}

// ---------------------------------------------------------------------------------------------
// Reader: one TOML table and its key path.

class Reader {
 public:
  Reader(const Source& src, const toml::node& node, std::string path)
      : src_(&src), table_(&to_table(src, node, path)), path_(std::move(path)) {}

  const Source& source() const { return *src_; }
  const std::string& path() const { return path_; }
  SourcePos pos() const { return src_->pos(*table_); }
  // Where key k is given; the table's position when it is not.
  SourcePos pos(std::string_view k) const {
    const toml::node* n = find(k);
    return src_->pos(n ? *n : *table_);
  }
  std::string key(std::string_view k) const {
    return path_.empty() ? std::string(k) : path_ + "." + std::string(k);
  }
  const toml::node* find(std::string_view k) const { return table_->get(k); }
  bool has(std::string_view k) const { return find(k) != nullptr; }

  // Fails at the key's value when present, else at the table (for a missing key).
  [[noreturn]] void fail(std::string_view k, const std::string& msg) const {
    const toml::node* n = find(k);
    src_->fail(n ? *n : *table_, key(k), msg);
  }
  [[noreturn]] void fail_table(const std::string& msg) const { src_->fail(*table_, path_, msg); }

  // Every key must be one of `allowed` (reports the first unknown key in file order).
  void allow_only(const KeyList& allowed) const {
    if (auto k = first_key_not_in(allowed))
      fail(*k, "unknown key " + in_quotes(*k) + did_you_mean(*k, allowed));
  }
  // Known keys outside `applicable` are errors "does not apply to <what>".
  void only_applicable(const KeyList& applicable, const std::string& what) const {
    if (auto k = first_key_not_in(applicable)) fail(*k, "does not apply to " + what);
  }

  const toml::node& required(std::string_view k) const {
    if (const toml::node* n = find(k)) return *n;
    fail(k, "required key is missing");
  }

  double number(std::string_view k, Range r) const {
    return to_number(*src_, required(k), key(k), r);
  }
  double number(std::string_view k, Range r, double fallback) const {
    return has(k) ? number(k, r) : fallback;
  }
  std::string string(std::string_view k) const {
    return to_string_value(*src_, required(k), key(k));
  }
  std::string string(std::string_view k, const std::string& fallback) const {
    return has(k) ? string(k) : fallback;
  }
  bool boolean(std::string_view k, bool fallback) const {
    const toml::node* n = find(k);
    if (!n) return fallback;
    if (const auto* b = n->as_boolean()) return b->get();
    fail(k, std::string("expected a boolean (true or false), got ") + type_name(*n));
  }
  Vec2 vec2(std::string_view k) const { return to_vec2(*src_, required(k), key(k)); }
  Vec2 vec2(std::string_view k, Vec2 fallback) const { return has(k) ? vec2(k) : fallback; }
  std::vector<double> numbers(std::string_view k) const {
    return to_numbers(*src_, required(k), key(k));
  }
  std::vector<std::string> strings(std::string_view k) const {
    const toml::array& a = to_array(*src_, required(k), key(k));
    std::vector<std::string> out;
    for (size_t i = 0; i < a.size(); ++i)
      out.push_back(to_string_value(*src_, a[i], key(k) + "[" + std::to_string(i) + "]"));
    return out;
  }

  template <class E>
  E choice(std::string_view k, const Choices<E>& choices) const {
    std::string s = string(k);
    for (const auto& c : choices)
      if (c.first == s) return c.second;
    std::vector<std::string_view> names = names_of(choices);
    fail(k, "unknown value " + in_quotes(s) + did_you_mean(s, names) +
                " (expected one of: " + join(names, ", ") + ")");
  }
  template <class E>
  E choice(std::string_view k, const Choices<E>& choices, E fallback) const {
    return has(k) ? choice(k, choices) : fallback;
  }

  Reader table(std::string_view k) const {
    if (!has(k)) fail(k, "required table is missing");
    return Reader(*src_, required(k), key(k));
  }
  std::optional<Reader> optional_table(std::string_view k) const {
    if (!has(k)) return std::nullopt;
    return table(k);
  }

  // Entries of an array of tables ([[k]] or k = [{...}, ...]); none when the key is absent.
  std::vector<Reader> entries(std::string_view k) const {
    std::vector<Reader> out;
    const toml::node* n = find(k);
    if (!n) return out;
    const toml::array* a = n->as_array();
    if (!a)
      fail(k, "expected an array of tables ([[" + std::string(k) + "]]), got " + type_name(*n));
    for (size_t i = 0; i < a->size(); ++i)
      out.emplace_back(*src_, (*a)[i], key(k) + entry_label((*a)[i], i));
    return out;
  }

 private:
  static std::string entry_label(const toml::node& entry, size_t index) {
    if (const toml::table* t = entry.as_table()) {
      if (const auto* name = t->get_as<std::string>("name"); name && !name->get().empty())
        return "['" + name->get() + "']";
    }
    return "[" + std::to_string(index) + "]";
  }

  std::optional<std::string> first_key_not_in(const KeyList& keys) const {
    std::optional<std::string> first;
    std::pair<int, int> first_at{std::numeric_limits<int>::max(), 0};
    for (auto&& [k, v] : *table_) {
      if (std::find(keys.begin(), keys.end(), k.str()) != keys.end()) continue;
      std::pair<int, int> at{static_cast<int>(k.source().begin.line),
                             static_cast<int>(k.source().begin.column)};
      if (!first || at < first_at) {
        first = std::string(k.str());
        first_at = at;
      }
    }
    return first;
  }

  const Source* src_;
  const toml::table* table_;
  std::string path_;
};

KeyList concat(KeyList a, const KeyList& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// ---------------------------------------------------------------------------------------------
// Names of materials, bodies and probes: uniqueness and references.

class Names {
 public:
  explicit Names(std::string what) : what_(std::move(what)) {}

  int size() const { return static_cast<int>(names_.size()); }

  // Adds the entry's name (key "name" of r); a duplicate is an error.
  void add(const Reader& r, const std::string& name) {
    auto it = std::find(names_.begin(), names_.end(), name);
    if (it != names_.end()) {
      int first_line = lines_[it - names_.begin()];
      r.fail("name", "duplicate " + what_ + " name " + in_quotes(name) + " (first defined " +
                         (first_line > 0 ? "on line " + std::to_string(first_line) : "by --set") +
                         ")");
    }
    names_.push_back(name);
    lines_.push_back(r.source().pos(*r.find("name")).line);
  }

  // Index of the entry named by r's key k; an unknown name is an error.
  int find(const Reader& r, std::string_view k, const std::string& name) const {
    auto it = std::find(names_.begin(), names_.end(), name);
    if (it != names_.end()) return static_cast<int>(it - names_.begin());
    std::vector<std::string_view> known(names_.begin(), names_.end());
    r.fail(k, "no " + what_ + " named " + in_quotes(name) + did_you_mean(name, known) +
                  (known.empty() ? "" : " (defined: " + join(known, ", ") + ")"));
  }

 private:
  std::string what_;
  std::vector<std::string> names_;
  std::vector<int> lines_;
};

std::string read_name(const Reader& r) {
  std::string name = r.string("name");
  if (name.empty()) r.fail("name", "must not be empty");
  if (name.find_first_of("./") != std::string::npos)
    r.fail("name", "must not contain '.' or '/' (got " + in_quotes(name) + ")");
  return name;
}

// ---------------------------------------------------------------------------------------------
// Geometry

double cross(Vec2 o, Vec2 a, Vec2 b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

bool on_segment(Vec2 p, Vec2 a, Vec2 b) {
  return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) &&
         std::min(a[1], b[1]) <= p[1] && p[1] <= std::max(a[1], b[1]);
}

// Closed segments ab and cd share a point.
bool segments_intersect(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return true;
  return (d1 == 0 && on_segment(a, c, d)) || (d2 == 0 && on_segment(b, c, d)) ||
         (d3 == 0 && on_segment(c, a, b)) || (d4 == 0 && on_segment(d, a, b));
}

void check_polygon(const Reader& r, const std::vector<Vec2>& p) {
  const size_t n = p.size();
  if (n < 3) r.fail("points", "a polygon needs at least 3 points (got " + std::to_string(n) + ")");
  auto edge = [&](size_t i) { return std::pair<Vec2, Vec2>{p[i], p[(i + 1) % n]}; };
  for (size_t i = 0; i < n; ++i) {
    auto [a, b] = edge(i);
    const Vec2& c = p[(i + 2) % n];
    if (a == b)
      r.fail("points",
             "points " + std::to_string(i) + " and " + std::to_string((i + 1) % n) + " coincide");
    double dot = (b[0] - a[0]) * (c[0] - b[0]) + (b[1] - a[1]) * (c[1] - b[1]);
    if (n > 3 && cross(a, b, c) == 0 && dot < 0)
      r.fail("points", "polygon folds back on itself at point " + std::to_string((i + 1) % n));
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      auto [c0, c1] = edge(j);
      if (segments_intersect(a, b, c0, c1))
        r.fail("points", "polygon is self-intersecting (edges " + std::to_string(i) + " and " +
                             std::to_string(j) + " cross)");
    }
  }
  double area2 = 0, extent = 0;
  for (size_t i = 0; i < n; ++i) {
    auto [a, b] = edge(i);
    area2 += a[0] * b[1] - b[0] * a[1];
    extent = std::max({extent, std::abs(a[0] - p[0][0]), std::abs(a[1] - p[0][1])});
  }
  if (std::abs(area2) <= 1e-12 * extent * extent)
    r.fail("points", "polygon is degenerate (zero area)");
}

// ---------------------------------------------------------------------------------------------
// Sections

const std::map<Shape::Type, KeyList> kShapeKeys = {
    {Shape::Type::rectangle, {"type", "x", "y", "width", "height"}},
    {Shape::Type::circle, {"type", "x", "y", "radius"}},
    {Shape::Type::semicircle, {"type", "x", "y", "radius", "angle"}},
    {Shape::Type::polygon, {"type", "points"}}};

Shape read_shape(const Reader& r) {
  r.allow_only({"type", "x", "y", "width", "height", "radius", "angle", "points"});
  Shape s;
  s.pos = r.pos();
  s.type = r.choice("type", kShapeTypes);
  r.only_applicable(kShapeKeys.at(s.type), "shape type " + in_quotes(name_of(kShapeTypes, s.type)));
  if (s.type == Shape::Type::polygon) {
    const toml::array& a = to_array(r.source(), r.required("points"), r.key("points"));
    for (size_t i = 0; i < a.size(); ++i)
      s.points.push_back(
          to_vec2(r.source(), a[i], r.key("points") + "[" + std::to_string(i) + "]"));
    check_polygon(r, s.points);
    return s;
  }
  s.x = r.number("x", Range::any());
  s.y = r.number("y", Range::any());
  if (s.type == Shape::Type::rectangle) {
    s.width = r.number("width", Range::gt(0));
    s.height = r.number("height", Range::gt(0));
  } else {
    s.radius = r.number("radius", Range::gt(0));
    if (s.type == Shape::Type::semicircle) s.angle_deg = r.number("angle", Range::any(), 90.0);
  }
  return s;
}

Segment read_segment(const Reader& r) {
  r.allow_only({"from", "to"});
  Segment s;
  s.pos = r.pos();
  s.from = r.vec2("from");
  s.to = r.vec2("to");
  if (s.from == s.to) r.fail_table("segment has zero length (from == to)");
  return s;
}

// Exactly one of `segment` and `shape`.
NodeSelector read_selector(const Reader& r) {
  NodeSelector w;
  if (r.has("segment") && r.has("shape")) r.fail("shape", "give 'segment' or 'shape', not both");
  if (r.has("shape")) {
    w.kind = NodeSelector::Kind::shape;
    w.shape = read_shape(r.table("shape"));
  } else if (r.has("segment")) {
    w.kind = NodeSelector::Kind::segment;
    w.segment = read_segment(r.table("segment"));
  } else {
    r.fail("segment", "required key is missing (give 'segment' or 'shape')");
  }
  return w;
}

SimulationParams read_simulation(const Reader& r) {
  r.allow_only({"title", "formulation", "thickness", "end_time", "dt_safety", "dt",
                "allow_unstable_dt", "output_interval", "history_interval", "hourglass",
                "hourglass_coefficient", "integration", "bulk_viscosity_linear",
                "bulk_viscosity_quadratic", "energy_error_limit", "conversion_interval", "seed",
                "conversion_on_tension"});
  SimulationParams s;
  s.pos = r.pos();
  if (r.has("dt")) s.dt_pos = r.pos("dt");
  s.title = r.string("title", s.title);
  s.formulation = r.choice("formulation", kFormulations, s.formulation);
  if (s.formulation == Formulation::plane_stress && !r.has("thickness"))
    r.fail("thickness", "required for formulation = \"plane_stress\"");
  if (s.formulation == Formulation::axisymmetric && r.has("thickness"))
    r.fail("thickness",
           "does not apply to formulation = \"axisymmetric\" (the model is the full revolution)");
  s.thickness = r.number("thickness", Range::gt(0), s.thickness);
  s.end_time = r.number("end_time", Range::gt(0));
  s.dt_safety = r.number("dt_safety", Range::gt(0).le(1), s.dt_safety);
  s.dt = r.number("dt", Range::gt(0), s.dt);
  s.allow_unstable_dt = r.boolean("allow_unstable_dt", s.allow_unstable_dt);
  s.output_interval = r.number("output_interval", Range::ge(0), s.output_interval);
  s.history_interval = r.number("history_interval", Range::ge(0), s.history_interval);
  s.hourglass = r.choice("hourglass", kHourglass, s.hourglass);
  s.hourglass_coefficient =
      r.number("hourglass_coefficient", Range::ge(0), s.hourglass_coefficient);
  s.integration = r.choice("integration", kIntegration, s.integration);
  s.bulk_viscosity_linear =
      r.number("bulk_viscosity_linear", Range::ge(0), s.bulk_viscosity_linear);
  s.bulk_viscosity_quadratic =
      r.number("bulk_viscosity_quadratic", Range::ge(0), s.bulk_viscosity_quadratic);
  s.energy_error_limit = r.number("energy_error_limit", Range::gt(0), s.energy_error_limit);
  // Bounded before the conversion to int: a larger double does not fit (undefined behaviour;
  // found by fuzz/fuzz_case.cpp). 10^9 steps is beyond any run.
  const double interval =
      r.number("conversion_interval", Range::ge(1).le(1e9), s.conversion_interval);
  if (interval != std::floor(interval))
    r.fail("conversion_interval", "must be a whole number of steps");
  s.conversion_interval = static_cast<int>(interval);
  s.conversion_on_tension = r.boolean("conversion_on_tension", s.conversion_on_tension);
  // Up to 2^53: every whole number a double holds exactly (TOML integers and floats alike).
  const double seed = r.number("seed", Range::ge(0).le(9007199254740992.0), 0.0);
  if (seed != std::floor(seed)) r.fail("seed", "must be a whole number");
  s.seed = static_cast<std::uint64_t>(seed);
  return s;
}

const KeyList kMaterialCommonKeys = {"name",
                                     "model",
                                     "density",
                                     "tensile_strength",
                                     "conversion_strain",
                                     "conversion_length_ratio",
                                     "weibull_modulus",
                                     "strength_spread",
                                     "rate_dependence"};
const std::map<MaterialModel, KeyList> kMaterialModelKeys = {
    {MaterialModel::elastic, {"youngs_modulus", "poisson_ratio", "fracture_energy"}},
    {MaterialModel::bilinear_j2,
     {"youngs_modulus", "poisson_ratio", "yield_stress", "plastic_modulus", "tangent_modulus"}},
    {MaterialModel::mohr_coulomb,
     {"youngs_modulus", "poisson_ratio", "cohesion", "friction_angle", "fracture_energy"}},
    {MaterialModel::hjc,
     {"shear_modulus", "compressive_strength", "hjc", "fracture_energy", "conversion_damage"}},
    {MaterialModel::johnson_cook,
     {"youngs_modulus", "poisson_ratio", "johnson_cook", "conversion_damage"}}};

// [[material]] model = "johnson_cook": youngs_modulus, poisson_ratio and the table
// johnson_cook = { A, B, n, C, m, melting_temperature, room_temperature, reference_strain_rate,
// specific_heat, taylor_quinney, D1, D2, D3, D4, D5 } in the symbols of Johnson & Cook (1983,
// 1985), SI units (A, B in Pa, temperatures in K, c_p in J/(kg K)).
void read_johnson_cook(const Reader& r, Material& m) {
  const Reader t = r.table("johnson_cook");
  t.allow_only({"A", "B", "n", "C", "m", "melting_temperature", "room_temperature",
                "reference_strain_rate", "specific_heat", "taylor_quinney", "D1", "D2", "D3", "D4",
                "D5"});
  JohnsonCookParams& j = m.jc;
  j.a = t.number("A", Range::gt(0));
  j.b = t.number("B", Range::ge(0));
  j.n = t.number("n", Range::gt(0).le(1));
  j.c = t.number("C", Range::ge(0));
  j.m = t.number("m", Range::gt(0));
  j.t_room = t.number("room_temperature", Range::gt(0), 293.0);
  j.t_melt = t.number("melting_temperature", Range::gt(j.t_room));
  j.eps0 = t.number("reference_strain_rate", Range::gt(0), 1.0);
  j.specific_heat = t.number("specific_heat", Range::ge(0), 0.0);
  j.taylor_quinney = t.number("taylor_quinney", Range::ge(0).le(1), 0.9);
  j.d1 = t.number("D1", Range::any(), 0.0);
  j.d2 = t.number("D2", Range::any(), 0.0);
  j.d3 = t.number("D3", Range::any(), 0.0);
  j.d4 = t.number("D4", Range::any(), 0.0);
  j.d5 = t.number("D5", Range::any(), 0.0);
}

// [[material]] model = "hjc": shear_modulus, compressive_strength (f'_c) and the table
// hjc = { A, B, N, C, S_max, reference_strain_rate, D1, D2, EF_min, p_crush, mu_crush, p_lock,
// mu_lock, K1, K2, K3 } in the symbols of Holmquist, Johnson & Cook (1993), SI units (pressures
// and K in Pa); tensile_strength is their T. Sets m.hjc and the elastic constants from G and
// K_e = p_crush / mu_crush.
void read_hjc(const Reader& r, Material& m) {
  const double G = r.number("shear_modulus", Range::gt(0));
  HjcParams& h = m.hjc;
  h.fc = r.number("compressive_strength", Range::gt(0));
  if (!(m.tensile_strength > 0.0)) r.fail("tensile_strength", "must be > 0 for model \"hjc\" (T)");
  h.t = m.tensile_strength;
  const Reader t = r.table("hjc");
  t.allow_only({"A", "B", "N", "C", "S_max", "reference_strain_rate", "D1", "D2", "EF_min",
                "p_crush", "mu_crush", "p_lock", "mu_lock", "K1", "K2", "K3"});
  h.a = t.number("A", Range::ge(0));
  h.b = t.number("B", Range::ge(0));
  h.n = t.number("N", Range::gt(0).le(1));
  h.c = t.number("C", Range::ge(0));
  h.s_max = t.number("S_max", Range::gt(0));
  h.eps0 = t.number("reference_strain_rate", Range::gt(0), 1.0);
  h.d1 = t.number("D1", Range::ge(0));
  h.d2 = t.number("D2", Range::ge(0));
  h.ef_min = t.number("EF_min", Range::gt(0));
  h.p_crush = t.number("p_crush", Range::gt(0));
  h.mu_crush = t.number("mu_crush", Range::gt(0).lt(1));
  h.p_lock = t.number("p_lock", Range::gt(h.p_crush));
  h.mu_lock = t.number("mu_lock", Range::gt(h.mu_crush).lt(1));
  h.k1 = t.number("K1", Range::gt(0));
  h.k2 = t.number("K2", Range::any());
  h.k3 = t.number("K3", Range::any());
  // Crushing must leave a plastic volumetric strain >= 0: both unloading moduli (K_e at its
  // start, K1 at its end) at least the slope of the crush line.
  const double k_elastic = h.p_crush / h.mu_crush;
  const double crush_slope = (h.p_lock - h.p_crush) / (h.mu_lock - h.mu_crush);
  if (k_elastic < crush_slope)
    t.fail("p_crush",
           "p_crush / mu_crush (" + fmt(k_elastic) +
               " Pa) must be at least the slope of the crush line to (mu_lock, p_lock) (" +
               fmt(crush_slope) + " Pa)");
  if (h.k1 < crush_slope)
    t.fail("K1", "must be at least the slope of the crush line (" + fmt(crush_slope) + " Pa)");
  // The fully dense curve must stiffen or hold: dP/dmu_bar = K1 + 2 K2 x + 3 K3 x^2 > 0 on
  // [0, 1] (x = 1 is a doubled density, beyond any impact).
  for (int i = 0; i <= 100; ++i) {
    const double x = i / 100.0;
    if (!(h.k1 + 2.0 * h.k2 * x + 3.0 * h.k3 * x * x > 0.0))
      t.fail("K2", "with K1 and K3 the fully dense pressure falls at mu_bar = " + fmt(x) +
                       " (dP/dmu_bar = K1 + 2 K2 mu_bar + 3 K3 mu_bar^2 must stay > 0)");
  }
  const double K = k_elastic;
  m.youngs_modulus = 9.0 * K * G / (3.0 * K + G);
  m.poisson_ratio = (3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G));
}

// Slope of stress vs plastic strain: `plastic_modulus` H, or from `tangent_modulus` Et.
double read_plastic_modulus(const Reader& r, double youngs_modulus) {
  if (r.has("plastic_modulus") && r.has("tangent_modulus"))
    r.fail("tangent_modulus", "give 'plastic_modulus' or 'tangent_modulus', not both");
  if (r.has("tangent_modulus")) {
    double et = r.number("tangent_modulus", Range::ge(0).lt(youngs_modulus));
    return youngs_modulus * et / (youngs_modulus - et);
  }
  if (!r.has("plastic_modulus"))
    r.fail("plastic_modulus", "required key is missing (or give 'tangent_modulus')");
  return r.number("plastic_modulus", Range::ge(0));
}

// [[material]] rate_dependence = { strain_rate = [...], strength = [...], fracture_energy = [...]
// }: dynamic increase factors (>= 1) at increasing strain rates (1/s); fracture_energy optional.
Material::RateTable read_rate_dependence(const Reader& r) {
  r.allow_only({"strain_rate", "strength", "fracture_energy"});
  Material::RateTable t;
  t.strain_rate = r.numbers("strain_rate");
  t.strength = r.numbers("strength");
  t.fracture_energy = r.has("fracture_energy") ? r.numbers("fracture_energy")
                                               : std::vector<double>(t.strain_rate.size(), 1.0);
  const size_t n = t.strain_rate.size();
  if (n < 1 || n > Material::RateTable::kMaxEntries)
    r.fail("strain_rate",
           "must have 1 to " + std::to_string(Material::RateTable::kMaxEntries) + " entries");
  for (const auto& [key, f] :
       {std::pair<const char*, const std::vector<double>&>{"strength", t.strength},
        {"fracture_energy", t.fracture_energy}}) {
    if (f.size() != n)
      r.fail(key, "has " + std::to_string(f.size()) + " entries but 'strain_rate' has " +
                      std::to_string(n));
    for (size_t i = 0; i < n; ++i)
      if (!(f[i] >= 1.0))
        r.fail(key, "dynamic increase factors must be >= 1 (" + std::string(key) + "[" +
                        std::to_string(i) + "] = " + fmt(f[i]) + ")");
  }
  for (size_t i = 0; i < n; ++i) {
    if (!(t.strain_rate[i] > 0.0))
      r.fail("strain_rate", "must be > 0 (strain_rate[" + std::to_string(i) +
                                "] = " + fmt(t.strain_rate[i]) + ")");
    if (i > 0 && !(t.strain_rate[i] > t.strain_rate[i - 1]))
      r.fail("strain_rate", "must be increasing (strain_rate[" + std::to_string(i) +
                                "] = " + fmt(t.strain_rate[i]) + ")");
  }
  return t;
}

Material read_material(const Reader& r, Names& names, Formulation formulation) {
  KeyList all = kMaterialCommonKeys;
  for (const auto& [model, keys] : kMaterialModelKeys) all = concat(all, keys);
  r.allow_only(all);
  Material m;
  m.pos = r.pos();
  m.name = read_name(r);
  names.add(r, m.name);
  m.model = r.choice("model", kModels);
  r.only_applicable(concat(kMaterialCommonKeys, kMaterialModelKeys.at(m.model)),
                    "model " + in_quotes(name_of(kModels, m.model)));
  m.density = r.number("density", Range::gt(0));
  const bool mc = m.model == MaterialModel::mohr_coulomb;
  const bool hjc = m.model == MaterialModel::hjc;
  const bool jc = m.model == MaterialModel::johnson_cook;
  m.tensile_strength = mc || hjc ? r.number("tensile_strength", Range::ge(0))
                                 : r.number("tensile_strength", Range::ge(0), 0.0);
  if (hjc) {
    if (formulation == Formulation::plane_stress)
      r.fail("model",
             "\"hjc\" needs simulation.formulation = \"plane_strain\" or \"axisymmetric\"");
    read_hjc(r, m);
  } else {
    m.youngs_modulus = r.number("youngs_modulus", Range::gt(0));
    m.poisson_ratio = r.number("poisson_ratio", Range::gt(-1).lt(0.5));
  }
  if (jc) read_johnson_cook(r, m);
  // hjc: its damage says when the concrete has fractured; its plastic strain under confinement
  // grows far beyond 0.02 without (the strain to fracture D1 (P* + T*)^D2 reaches 1 at
  // P* = 25), so the default converts by damage and leaves the plastic strain to flow.
  m.conversion_strain = r.number("conversion_strain", Range::gt(0), hjc ? 1e300 : mc ? 0.02 : 0.5);
  if (hjc) m.conversion_damage = r.number("conversion_damage", Range::gt(0).le(1), 1.0);
  // johnson_cook: by its failure strain when it has one (D1..D5 not all 0).
  if (jc) {
    const JohnsonCookParams& j = m.jc;
    const bool failure = j.d1 != 0 || j.d2 != 0 || j.d3 != 0 || j.d4 != 0 || j.d5 != 0;
    if (r.has("conversion_damage") && !failure)
      r.fail("conversion_damage", "needs the failure constants D1..D5 of johnson_cook");
    if (failure) m.conversion_damage = r.number("conversion_damage", Range::gt(0).le(1), 1.0);
  }
  m.conversion_length_ratio =
      r.number("conversion_length_ratio", Range::ge(0).lt(1), kDefaultConversionLengthRatio);
  if (m.model == MaterialModel::bilinear_j2) {
    m.yield_stress = r.number("yield_stress", Range::gt(0));
    m.plastic_modulus = read_plastic_modulus(r, m.youngs_modulus);
  } else if (mc) {
    m.cohesion = r.number("cohesion", Range::gt(0));
    m.friction_angle = r.number("friction_angle", Range::ge(0).lt(90)) * kPi / 180.0;
  }
  // Quasi-brittle bonds soften over an opening 2 G_f / sigma_t after reaching the strength
  // (bond_forces.hpp); bilinear_j2 bonds are elastoplastic instead (docs/physics.md 1.2).
  m.fracture_energy = r.number("fracture_energy", Range::ge(0), 0.0);
  if (m.fracture_energy > 0.0 && !(m.tensile_strength > 0.0))
    r.fail("fracture_energy", "needs a tensile_strength > 0 (the softening starts there)");
  m.weibull_modulus = r.number("weibull_modulus", Range::ge(0).le(1000), 0.0);
  if (m.weibull_modulus > 0.0 && m.weibull_modulus < 1.0)
    r.fail("weibull_modulus", "must be 0 (uniform strength) or at least 1");
  m.strength_spread = r.number("strength_spread", Range::ge(0).lt(1), 0.0);
  if (m.strength_spread > 0.0 && m.weibull_modulus > 0.0)
    r.fail("strength_spread", "give either weibull_modulus or strength_spread, not both");
  if (m.random_strength() && !(m.tensile_strength > 0.0 || m.cohesion > 0.0))
    r.fail(m.weibull_modulus > 0.0 ? "weibull_modulus" : "strength_spread",
           "needs a tensile_strength or cohesion > 0 (it scales them)");
  if (const auto rate = r.optional_table("rate_dependence")) {
    m.rate_dependence = read_rate_dependence(*rate);
    if (!(m.tensile_strength > 0.0 || m.cohesion > 0.0))
      r.fail("rate_dependence", "needs a tensile_strength or cohesion > 0 (it scales them)");
    if (rate->has("fracture_energy") && !(m.fracture_energy > 0.0))
      rate->fail("fracture_energy", "needs the material's fracture_energy > 0");
  }
  return m;
}

ContactParams read_contact(const Reader& r) {
  r.allow_only({"stiffness_factor", "damping_ratio", "friction"});
  ContactParams c;
  c.stiffness_factor = r.number("stiffness_factor", Range::gt(0), c.stiffness_factor);
  c.damping_ratio = r.number("damping_ratio", Range::ge(0).le(1), c.damping_ratio);
  c.friction = r.number("friction", Range::ge(0), c.friction);
  return c;
}

Region read_region(const Reader& r) {
  r.allow_only({"method", "shape"});
  Region g;
  g.pos = r.pos();
  g.method = r.choice("method", kMethods);
  g.shape = read_shape(r.table("shape"));
  return g;
}

Body read_body(const Reader& r, Names& names, const Names& materials) {
  r.allow_only({"name", "material", "method", "cell_size", "shape", "cut", "region",
                "initial_velocity", "initial_velocity_gradient", "initial_velocity_origin",
                "node_perturbation"});
  Body b;
  b.pos = r.pos();
  b.name = read_name(r);
  names.add(r, b.name);
  b.material = r.string("material");
  b.material_index = materials.find(r, "material", b.material);
  b.method = r.choice("method", kMethods, b.method);
  b.cell_size = r.number("cell_size", Range::gt(0));
  b.shape = read_shape(r.table("shape"));
  for (const Reader& c : r.entries("cut")) b.cuts.push_back(read_shape(c));
  for (const Reader& g : r.entries("region")) b.regions.push_back(read_region(g));
  b.initial_velocity = r.vec2("initial_velocity", b.initial_velocity);
  if (r.has("initial_velocity_gradient")) {
    const std::string key = r.key("initial_velocity_gradient");
    const toml::array& rows = to_array(r.source(), r.required("initial_velocity_gradient"), key);
    if (rows.size() != 2)
      r.fail("initial_velocity_gradient",
             "expected [[dvx/dx, dvx/dy], [dvy/dx, dvy/dy]] (2 rows), got " +
                 std::to_string(rows.size()));
    for (size_t i = 0; i < 2; ++i)
      b.initial_velocity_gradient[i] =
          to_vec2(r.source(), rows[i], key + "[" + std::to_string(i) + "]");
  }
  b.initial_velocity_origin = r.vec2("initial_velocity_origin", b.initial_velocity_origin);
  // Up to a quarter cell: every cell stays convex with room to spare (a corner would have to
  // cross its neighbours' diagonal, 0.71 cell away, to fold it).
  b.node_perturbation =
      r.number("node_perturbation", Range::ge(0).le(kMaxNodePerturbation), b.node_perturbation);
  const auto& L = b.initial_velocity_gradient;
  if (b.method == BodyMethod::rigid &&
      (L[0][0] != 0 || L[0][1] != 0 || L[1][0] != 0 || L[1][1] != 0))
    r.fail("initial_velocity_gradient", "does not apply to a rigid body (it keeps its shape)");
  return b;
}

// The piecewise-linear table of a load: `time` (non-decreasing, >= 0) and `value`.
template <class Table>
void read_history(const Reader& r, Table& l) {
  l.time = r.numbers("time");
  l.value = r.numbers("value");
  if (l.time.empty()) r.fail("time", "must have at least one entry");
  if (l.value.size() != l.time.size())
    r.fail("value", "has " + std::to_string(l.value.size()) + " entries but 'time' has " +
                        std::to_string(l.time.size()));
  for (size_t i = 0; i < l.time.size(); ++i) {
    if (l.time[i] < 0)
      r.fail("time", "must be >= 0 (time[" + std::to_string(i) + "] = " + fmt(l.time[i]) + ")");
    if (i > 0 && l.time[i] < l.time[i - 1])
      r.fail("time", "must be non-decreasing (time[" + std::to_string(i) + "] = " + fmt(l.time[i]) +
                         " < time[" + std::to_string(i - 1) + "] = " + fmt(l.time[i - 1]) + ")");
  }
}

Load read_load(const Reader& r, const Names& bodies) {
  r.allow_only({"body", "type", "segment", "shape", "direction", "time", "value"});
  Load l;
  l.pos = r.pos();
  l.body = r.string("body");
  l.body_index = bodies.find(r, "body", l.body);
  l.type = r.choice("type", kLoadTypes);
  if (l.type == Load::Type::pressure) {
    r.only_applicable({"body", "type", "segment", "time", "value"}, "load type 'pressure'");
    l.where.kind = NodeSelector::Kind::segment;
    l.where.segment = read_segment(r.table("segment"));
  } else {
    if (l.type == Load::Type::traction) {
      r.only_applicable({"body", "type", "segment", "direction", "time", "value"},
                        "load type 'traction'");
      l.where.kind = NodeSelector::Kind::segment;
      l.where.segment = read_segment(r.table("segment"));
    } else {
      l.where = read_selector(r);
    }
    Vec2 d = r.vec2("direction");
    double norm = std::hypot(d[0], d[1]);
    if (!(norm > 0)) r.fail("direction", "must be a non-zero vector");
    l.direction = {d[0] / norm, d[1] / norm};
  }
  read_history(r, l);
  return l;
}

Boundary read_boundary(const Reader& r, const Names& bodies, Names& names) {
  r.allow_only({"name", "body", "type", "segment", "shape", "component", "direction", "time",
                "value", "impedance", "area"});
  Boundary b;
  b.pos = r.pos();
  if (r.has("name")) {
    b.name = read_name(r);
    names.add(r, b.name);
  }
  b.body = r.string("body", "");
  if (r.has("body")) b.body_index = bodies.find(r, "body", b.body);
  b.type = r.choice("type", kBoundaryTypes);
  const KeyList common = {"name", "body", "type", "segment", "shape"};
  auto applicable = [&](std::initializer_list<std::string_view> more, const char* what) {
    KeyList keys = common;
    keys.insert(keys.end(), more.begin(), more.end());
    r.only_applicable(keys, what);
  };
  switch (b.type) {
    case Boundary::Type::fixed_x:
    case Boundary::Type::fixed_y:
    case Boundary::Type::fixed:
      applicable({}, "a fixed boundary");
      break;
    case Boundary::Type::velocity: {
      applicable({"component", "time", "value"}, "boundary type 'velocity'");
      const std::string c = r.string("component");
      if (c != "x" && c != "y") r.fail("component", "must be \"x\" or \"y\", got \"" + c + "\"");
      b.component = c == "x" ? 0 : 1;
      read_history(r, b);
      break;
    }
    case Boundary::Type::support: {
      applicable({"direction"}, "boundary type 'support'");
      const Vec2 d = r.vec2("direction");
      // Held components are the solver's per-axis constraint: a support pushes along an axis.
      const bool axis = (d[0] == 0.0) != (d[1] == 0.0);
      if (!axis)
        r.fail("direction", "a support pushes along x or y: [1, 0], [-1, 0], [0, 1] or [0, -1]");
      b.direction = {d[0] == 0.0 ? 0.0 : std::copysign(1.0, d[0]),
                     d[1] == 0.0 ? 0.0 : std::copysign(1.0, d[1])};
      break;
    }
    case Boundary::Type::bar: {
      applicable({"direction", "impedance", "area", "time", "value"}, "boundary type 'bar'");
      const Vec2 d = r.vec2("direction");
      const double norm = std::hypot(d[0], d[1]);
      if (!(norm > 0)) r.fail("direction", "must be a non-zero vector");
      b.direction = {d[0] / norm, d[1] / norm};
      b.impedance = r.number("impedance", Range::gt(0));
      b.area = r.number("area", Range::gt(0));
      if (r.has("time") || r.has("value")) {
        read_history(r, b);
      } else {
        b.time = {0.0};  // a transmitted bar: no incident wave
        b.value = {0.0};
      }
      break;
    }
  }
  b.where = read_selector(r);
  return b;
}

Probe read_probe(const Reader& r, Names& names, const Names& bodies) {
  r.allow_only({"name", "at", "body"});
  Probe p;
  p.pos = r.pos();
  p.name = read_name(r);
  names.add(r, p.name);
  p.at = r.vec2("at");
  p.body = r.string("body", "");
  if (r.has("body")) p.body_index = bodies.find(r, "body", p.body);
  return p;
}

BodyProbe read_body_probe(const Reader& r, Names& names, const Names& bodies) {
  r.allow_only({"name", "body"});
  BodyProbe p;
  p.pos = r.pos();
  p.name = read_name(r);
  names.add(r, p.name);
  p.body = r.string("body");
  p.body_index = bodies.find(r, "body", p.body);
  return p;
}

OutputParams read_output(const Reader& r) {
  r.allow_only({"file", "fields", "checkpoint_interval", "precision", "compression"});
  OutputParams o;
  o.file = r.string("file", o.file);
  if (o.file.empty()) r.fail("file", "must not be empty");
  if (r.has("fields")) o.fields = r.strings("fields");
  for (size_t i = 0; i < o.fields.size(); ++i) {
    const std::string& f = o.fields[i];
    if (std::find(kOutputFields.begin(), kOutputFields.end(), f) == kOutputFields.end())
      r.fail("fields", "unknown field " + in_quotes(f) + did_you_mean(f, kOutputFields) +
                           " (expected some of: " + join(kOutputFields, ", ") + ")");
    if (std::find(o.fields.begin(), o.fields.begin() + i, f) != o.fields.begin() + i)
      r.fail("fields", "field " + in_quotes(f) + " is listed twice");
  }
  o.checkpoint_interval = r.number("checkpoint_interval", Range::ge(0), o.checkpoint_interval);
  o.single_precision = r.choice("precision", kPrecisions, o.single_precision);
  const double level = r.number("compression", Range::ge(0).le(9), o.compression);
  if (level != std::floor(level)) r.fail("compression", "must be a whole number from 0 to 9");
  o.compression = static_cast<int>(level);
  return o;
}

void read_case(const Reader& r, Case& c) {
  r.allow_only({"simulation", "material", "contact", "body", "load", "boundary", "probe",
                "body_probe", "output"});
  c.sim = read_simulation(r.table("simulation"));

  Names materials("material");
  for (const Reader& e : r.entries("material"))
    c.materials.push_back(read_material(e, materials, c.sim.formulation));
  if (c.materials.empty()) r.fail("material", "at least one [[material]] is required");

  if (auto t = r.optional_table("contact")) c.contact = read_contact(*t);

  Names bodies("body");
  const std::vector<Reader> body_entries = r.entries("body");
  for (const Reader& e : body_entries) c.bodies.push_back(read_body(e, bodies, materials));
  if (c.bodies.empty()) r.fail("body", "at least one [[body]] is required");
  if (c.sim.formulation == Formulation::axisymmetric) {
    // Axisymmetric bodies are finite elements, rings of discs (docs/physics.md 1.2,
    // "Axisymmetric discs") or rigid bodies of revolution, which can only translate along the
    // axis (docs/case-file.md, "formulation").
    for (size_t i = 0; i < c.bodies.size(); ++i) {
      const Body& b = c.bodies[i];
      if (b.method == BodyMethod::rigid && b.initial_velocity[0] != 0.0)
        body_entries[i].fail("initial_velocity",
                             "a rigid body of revolution (formulation = \"axisymmetric\") moves "
                             "along the axis only: its x (radial) component must be 0");
      if (shape_bounds(b.shape)[0] < 0.0)
        body_entries[i].fail("shape",
                             "reaches x < 0: in formulation = \"axisymmetric\" x is the radius");
    }
  }
  {
    // An impact faster than kMaxClosingSpeedRatio times the materials' P-wave speed is refused:
    // nothing of a solid survives it (meteoroids, the fastest natural impacts, strike rock at
    // up to about 70 km/s, about 10 times its P-wave speed), and the solver's step would let
    // the bodies pass through each other.
    const ClosingSpeed closing = initial_closing_speed(c);
    const double limit = kMaxClosingSpeedRatio * largest_p_wave_speed(c);
    if (closing.faster >= 0 && closing.speed > limit) {
      char what[320];
      std::snprintf(what, sizeof what,
                    "closes on body '%s' at %.4g m/s, more than %.0f times the largest P-wave "
                    "speed of the materials (%.4g m/s): no solid's law applies at such speeds",
                    c.bodies[closing.slower].name.c_str(), closing.speed, kMaxClosingSpeedRatio,
                    limit / kMaxClosingSpeedRatio);
      body_entries[closing.faster].fail(body_entries[closing.faster].has("initial_velocity")
                                            ? "initial_velocity"
                                            : "initial_velocity_gradient",
                                        what);
    }
  }

  for (const Reader& e : r.entries("load")) c.loads.push_back(read_load(e, bodies));
  Names boundary_names("boundary");
  for (const Reader& e : r.entries("boundary"))
    c.boundaries.push_back(read_boundary(e, bodies, boundary_names));
  Names probes("probe"), body_probes("body_probe");
  for (const Reader& e : r.entries("probe")) c.probes.push_back(read_probe(e, probes, bodies));
  for (const Reader& e : r.entries("body_probe"))
    c.body_probes.push_back(read_body_probe(e, body_probes, bodies));
  if (auto t = r.optional_table("output")) c.output = read_output(*t);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Initial closing speed

namespace {
Vec2 centre_velocity(const Body& b) {
  const std::array<double, 4> box = shape_bounds(b.shape);
  const Vec2 x{0.5 * (box[0] + box[2]), 0.5 * (box[1] + box[3])};
  const auto& L = b.initial_velocity_gradient;
  const Vec2& o = b.initial_velocity_origin;
  return {b.initial_velocity[0] + L[0][0] * (x[0] - o[0]) + L[0][1] * (x[1] - o[1]),
          b.initial_velocity[1] + L[1][0] * (x[0] - o[0]) + L[1][1] * (x[1] - o[1])};
}
}  // namespace

ClosingSpeed initial_closing_speed(const Case& c) {
  ClosingSpeed out;
  std::vector<Vec2> v;
  for (const Body& b : c.bodies) v.push_back(centre_velocity(b));
  for (size_t a = 0; a < v.size(); ++a)
    for (size_t b = a + 1; b < v.size(); ++b) {
      const double speed = std::hypot(v[a][0] - v[b][0], v[a][1] - v[b][1]);
      if (speed <= out.speed) continue;
      const bool a_faster = std::hypot(v[a][0], v[a][1]) >= std::hypot(v[b][0], v[b][1]);
      out = {speed, static_cast<int>(a_faster ? a : b), static_cast<int>(a_faster ? b : a)};
    }
  return out;
}

double largest_p_wave_speed(const Case& c) {
  double speed = 0;
  for (const Material& m : c.materials) {
    const double nu = m.poisson_ratio;
    speed = std::max(
        speed, std::sqrt(m.youngs_modulus * (1 - nu) / ((1 + nu) * (1 - 2 * nu) * m.density)));
  }
  return speed;
}

namespace {

// ---------------------------------------------------------------------------------------------
// Parsing and --set overrides

// TOML allows non-ASCII text only in strings and comments. toml++ 3.3.0 classifies a non-ASCII
// code point met elsewhere with a lookup that reaches __builtin_unreachable() for most of
// U+00A1..U+0499 and U+2D6E..U+3168 (undefined behaviour; found by fuzz/fuzz_case.cpp), so such
// text is refused here, with the position, before toml++ sees it.
void reject_bare_non_ascii(const std::string& text, const std::string& source_name) {
  enum class In { bare, comment, basic, literal, multi_basic, multi_literal } in = In::bare;
  int line = 1, column = 0;
  char prev = '\n';  // the last character outside strings and comments that is not a blank
  for (size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    ++column;
    if (ch == '\n') {
      ++line;
      column = 0;
      if (in != In::multi_basic && in != In::multi_literal) prev = '\n';
      if (in == In::comment || in == In::basic || in == In::literal) in = In::bare;
      continue;
    }
    // Control characters are not TOML anywhere (not even in strings or comments), and after a
    // NUL toml++ and this scan no longer agree on what is a string (fuzz reproducer).
    const auto byte = static_cast<unsigned char>(ch);
    if ((byte < 0x20 && ch != '\t' && ch != '\r') || byte == 0x7f)
      throw InputError(source_name, line, "",
                       "TOML syntax error (column " + std::to_string(column) +
                           "): control character U+00" + "0123456789ABCDEF"[byte >> 4] +
                           "0123456789ABCDEF"[byte & 15] + " is not allowed");
    const bool triple = text.compare(i, 3, std::string(3, ch)) == 0;
    switch (in) {
      case In::bare:
        if (static_cast<unsigned char>(ch) >= 0x80)
          throw InputError(source_name, line, "",
                           "TOML syntax error (column " + std::to_string(column) +
                               "): a non-ASCII character outside a string or comment");
        if (ch == '#') in = In::comment;
        // A quote opens a string only where TOML allows one (a key or a value: first on the
        // line, or after = [ , { .); elsewhere toml++ does not read a string either (fuzz).
        if ((ch == '"' || ch == '\'') && std::strchr("\n=[,{.", prev) != nullptr) {
          if (ch == '"') in = triple ? In::multi_basic : In::basic;
          if (ch == '\'') in = triple ? In::multi_literal : In::literal;
          if (triple) i += 2;
        }
        if (ch != ' ' && ch != '\t') prev = ch;
        break;
      case In::comment:
        break;
      case In::basic:
      case In::multi_basic:
        if (ch == '\\') {
          ++i;  // the escaped character (a newline after it is counted below)
          if (i < text.size() && text[i] == '\n') --i;
        } else if (ch == '"' && (in == In::basic || triple)) {
          in = In::bare;
          if (triple) i += 2;
        }
        break;
      case In::literal:
      case In::multi_literal:
        if (ch == '\'' && (in == In::literal || triple)) {
          in = In::bare;
          if (triple) i += 2;
        }
        break;
    }
  }
}

toml::table parse_toml(const std::string& text, const std::string& source_name) {
  reject_bare_non_ascii(text, source_name);
  try {
    return toml::parse(std::string_view(text), std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    throw InputError(source_name, static_cast<int>(e.source().begin.line), "",
                     "TOML syntax error (column " + std::to_string(e.source().begin.column) +
                         "): " + std::string(e.description()));
  }
}

std::string trim(std::string_view s) {
  const char* ws = " \t\r\n";
  size_t b = s.find_first_not_of(ws);
  if (b == std::string_view::npos) return "";
  return std::string(s.substr(b, s.find_last_not_of(ws) - b + 1));
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::istringstream in(s);
  std::string part;
  while (std::getline(in, part, sep)) parts.push_back(trim(part));
  if (!s.empty() && s.back() == sep) parts.emplace_back();
  return parts;
}

// The override's value as TOML ("1e-6", "\"x.h5\"", "[0, 1]"), else as a bare string.
toml::table parse_override_value(const std::string& text) {
  try {
    reject_bare_non_ascii("value = " + text, kOverrideSource);
    toml::table doc =
        toml::parse(std::string_view("value = " + text), std::string_view(kOverrideSource));
    if (doc.size() == 1) return doc;
  } catch (const toml::parse_error&) {
  } catch (const InputError&) {  // not TOML: taken as a bare string
  }
  toml::table doc;
  doc.insert("value", text);
  return doc;
}

// The entry of an array of tables addressed by its name (or, failing that, its index).
toml::table* select_entry(toml::array& entries, const std::string& selector,
                          const std::string& section, const std::string& key) {
  std::vector<std::string_view> names;
  for (toml::node& e : entries) {
    toml::table* t = e.as_table();
    const auto* name = t ? t->get_as<std::string>("name") : nullptr;
    if (!name) continue;
    if (name->get() == selector) return t;
    names.push_back(name->get());
  }
  bool digits =
      !selector.empty() && std::all_of(selector.begin(), selector.end(),
                                       [](unsigned char ch) { return std::isdigit(ch) != 0; });
  if (digits && selector.size() < 9 && std::stoul(selector) < entries.size()) {
    if (toml::table* t = entries[std::stoul(selector)].as_table()) return t;
  }
  throw InputError(kOverrideSource, 0, key,
                   "no [[" + section + "]] entry named " + in_quotes(selector) +
                       did_you_mean(selector, names) + " (entries are addressed by name or index)");
}

// Applies "a.b.c=value" to the tree; the new nodes are marked as coming from --set.
void apply_override(toml::table& root, const std::string& spec, Source& src) {
  size_t eq = spec.find('=');
  if (eq == std::string::npos)
    throw InputError(kOverrideSource, 0, trim(spec),
                     "expected KEY=VALUE (e.g. simulation.end_time=1e-6)");
  const std::string key = trim(spec.substr(0, eq));
  std::vector<std::string> parts = split(key, '.');
  if (parts.empty() || std::any_of(parts.begin(), parts.end(), [](auto& p) { return p.empty(); }))
    throw InputError(kOverrideSource, 0, key, "malformed key (expected e.g. simulation.end_time)");

  toml::table* t = &root;
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    toml::node* n = t->get(parts[i]);
    if (!n) {
      auto [it, inserted] = t->insert(parts[i], toml::table{});
      src.mark_override(it->second);
      t = it->second.as_table();
    } else if (toml::table* sub = n->as_table()) {
      t = sub;
    } else if (toml::array* entries = n->as_array()) {
      if (i + 2 >= parts.size())
        throw InputError(kOverrideSource, 0, key,
                         "entries of [[" + parts[i] + "]] are addressed as " + parts[i] +
                             ".NAME.KEY or " + parts[i] + ".INDEX.KEY");
      t = select_entry(*entries, parts[i + 1], parts[i], key);
      ++i;
    } else {
      throw InputError(kOverrideSource, 0, key,
                       in_quotes(parts[i]) + " is " + type_name(*n) + ", not a table");
    }
  }
  toml::table value = parse_override_value(trim(spec.substr(eq + 1)));
  t->insert_or_assign(parts.back(), *value.get("value"));
  src.mark_override(*t->get(parts.back()));
}

}  // namespace

Case parse_case(const std::string& text, const std::string& source_name,
                const std::vector<std::string>& overrides) {
  Source src(source_name);
  toml::table root = parse_toml(text, source_name);
  for (const std::string& o : overrides) apply_override(root, o, src);
  Case c;
  c.path = source_name;
  c.text = text;
  c.overrides = overrides;
  read_case(Reader(src, root, ""), c);
  return c;
}

Case load_case(const std::string& path, const std::vector<std::string>& overrides) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw InputError(path, 0, "", "cannot read the case file: it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError(path, 0, "",
                     std::string("cannot open the case file: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path, 0, "", "cannot read the case file");
  return parse_case(text.str(), path, overrides);
}

namespace {

// Keys a restart may change: they do not define the model (docs/case-file.md).
bool restart_may_change(const std::string& key) {
  return key == "output" || key == "simulation.end_time" || key == "simulation.output_interval" ||
         key == "simulation.history_interval" || key == "simulation.title";
}

// The first key under `prefix` where a and b differ ("" if none); `where` gets the node of b
// to point at (or of its parent when b lacks the key).
std::string first_difference(const toml::node& a, const toml::node& b, const std::string& prefix,
                             const toml::node*& where) {
  if (restart_may_change(prefix)) return "";
  where = &b;
  const toml::table *ta = a.as_table(), *tb = b.as_table();
  const toml::array *aa = a.as_array(), *ab = b.as_array();
  if (ta && tb) {
    for (auto&& [k, va] : *ta) {
      const std::string key =
          prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
      if (restart_may_change(key)) continue;
      const toml::node* vb = tb->get(k.str());
      if (!vb) return key;
      const std::string d = first_difference(va, *vb, key, where);
      if (!d.empty()) return d;
      where = &b;
    }
    for (auto&& [k, vb] : *tb) {
      const std::string key =
          prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
      if (!restart_may_change(key) && !ta->get(k.str())) {
        where = &vb;
        return key;
      }
    }
    return "";
  }
  if (aa && ab) {
    if (aa->size() != ab->size()) return prefix;
    for (size_t i = 0; i < aa->size(); ++i) {
      // Entries of an array of tables are named as --set addresses them: body.NAME.key.
      const toml::table* entry = aa->get(i)->as_table();
      const auto* name = entry ? entry->get_as<std::string>("name") : nullptr;
      const std::string sub =
          entry ? prefix + "." + (name ? name->get() : std::to_string(i)) : prefix;
      const std::string d = first_difference(*aa->get(i), *ab->get(i), sub, where);
      if (!d.empty()) return d;
      where = &b;
    }
    return "";
  }
  return toml::node_view<const toml::node>(&a) == toml::node_view<const toml::node>(&b) ? ""
                                                                                        : prefix;
}

}  // namespace

void check_restart_compatible(const Case& stored, const Case& now) {
  Source stored_src(stored.path), now_src(now.path);
  toml::table a = parse_toml(stored.text, stored.path);
  for (const std::string& o : stored.overrides) apply_override(a, o, stored_src);
  toml::table b = parse_toml(now.text, now.path);
  for (const std::string& o : now.overrides) apply_override(b, o, now_src);
  const toml::node* where = &b;
  const std::string key = first_difference(a, b, "", where);
  if (key.empty()) return;
  const SourcePos p = now_src.pos(*where);
  throw InputError(p.file, p.line, key,
                   "differs from the case the checkpoint was written with (" + stored.path +
                       "): a restart may change only simulation.end_time, output_interval, "
                       "history_interval, title and [output]");
}

const char* to_string(Formulation f) {
  return name_of(kFormulations, f);
}
const char* to_string(MaterialModel m) {
  return name_of(kModels, m);
}
const char* to_string(BodyMethod m) {
  return name_of(kMethods, m);
}

}  // namespace fracta
