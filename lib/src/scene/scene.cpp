// Scene files. nlohmann parses the JSON but (in 3.11) keeps no positions, so a small scan of the
// same text, run once nlohmann has accepted it, finds the line of every value and key that a
// message may name.
#include "snag/scene/scene.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "snag/error.h"

namespace snag::scene {
namespace fs = std::filesystem;
using nlohmann::ordered_json;  // keys in file order, so that the first mistake is reported first

namespace {

constexpr std::string_view kSchema = "snag-scene/1";

/// 1-based line of the byte at `offset`.
int64_t line_at(std::string_view text, size_t offset) {
  offset = std::min(offset, text.size());
  return 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(offset), '\n');
}

std::string member_path(const std::string& parent, std::string_view key) {
  return parent.empty() ? std::string(key) : parent + "." + std::string(key);
}

std::string element_path(const std::string& parent, size_t index) {
  return parent + "[" + std::to_string(index) + "]";
}

/// Where the values and object keys of a text that nlohmann accepted start, by key path
/// ("objects[1].role"); also rejects duplicate keys, which nlohmann would silently resolve to the
/// last. Iterative, and paths are built only kMaxDepth levels deep (a scene's keys are at most 5
/// deep), so that pathological nesting costs neither stack nor quadratic memory.
class Positions {
 public:
  Positions(std::string_view text, const std::string& file);
  /// Line of the value at `path`, or of its key (`at_key`); 0 when unknown.
  int64_t line(const std::string& path, bool at_key) const {
    const auto it = where_.find(path);
    if (it == where_.end()) return 0;
    const size_t offset = at_key ? it->second.key : it->second.value;
    return offset == kNone ? 0 : line_at(text_, offset);
  }

 private:
  static constexpr size_t kNone = static_cast<size_t>(-1);
  static constexpr size_t kMaxDepth = 8;
  struct Where {
    size_t value = kNone;
    size_t key = kNone;
  };

  char at(size_t i) const { return i < text_.size() ? text_[i] : '\0'; }
  size_t skip_space(size_t i) const {
    while (at(i) == ' ' || at(i) == '\t' || at(i) == '\n' || at(i) == '\r') ++i;
    return i;
  }
  /// From an opening quote to just past the closing one.
  size_t skip_string(size_t i) const {
    for (++i; i < text_.size() && text_[i] != '"'; ++i)
      if (text_[i] == '\\') ++i;
    return i + 1;
  }
  /// A number, true, false or null.
  size_t skip_scalar(size_t i) const {
    while (i < text_.size() && std::strchr(" \t\r\n,]}", text_[i]) == nullptr) ++i;
    return i;
  }

  std::string_view text_;
  std::map<std::string, Where> where_;
};

Positions::Positions(std::string_view text, const std::string& file) : text_(text) {
  struct Container {
    bool object;
    bool recorded;     // whether paths below it are built
    std::string path;  // empty when not recorded
    size_t count = 0;
    std::set<std::string> keys;
  };
  std::vector<Container> stack;
  size_t i = text.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // nlohmann skips a UTF-8 BOM too
  i = skip_space(i);
  std::string path;  // of the value that starts at i
  bool recorded = true;

  // At the start of the next member or element of the innermost container: moves i to its value.
  auto begin_item = [&] {
    Container& c = stack.back();
    const size_t index = c.count++;
    recorded = c.recorded;
    if (!c.object) {
      if (recorded) path = element_path(c.path, index);
      return;
    }
    const size_t key_start = i;
    i = skip_string(i);
    if (recorded) {
      const std::string_view raw = text_.substr(key_start, i - key_start);
      const std::string key = raw.find('\\') == std::string_view::npos
                                  ? std::string(raw.substr(1, raw.size() - 2))
                                  : ordered_json::parse(raw.begin(), raw.end()).get<std::string>();
      path = member_path(c.path, key);
      if (!c.keys.insert(key).second) {
        throw InputError(file, line_at(text_, key_start),
                         path + ": duplicate key (the first is on line " +
                             std::to_string(line(path, true)) + ")");
      }
      where_[path].key = key_start;
    }
    i = skip_space(skip_space(i) + 1);  // past ':'
  };

  for (;;) {
    if (recorded) where_[path].value = i;
    const char c = at(i);
    bool finished = true;  // whether the value ends at i
    if (c == '{' || c == '[') {
      const bool record_below = recorded && stack.size() + 1 < kMaxDepth;
      stack.push_back({c == '{', record_below, record_below ? path : std::string(), 0, {}});
      i = skip_space(i + 1);
      if (at(i) == '}' || at(i) == ']') {
        ++i;
        stack.pop_back();
      } else {
        finished = false;
      }
    } else if (c == '"') {
      i = skip_string(i);
    } else {
      i = skip_scalar(i);
    }
    if (finished) {
      // Close the containers this value ends, up to one with a next item.
      for (;;) {
        i = skip_space(i);
        if (stack.empty() || i >= text_.size()) return;
        if (at(i) == ',') {
          i = skip_space(i + 1);
          break;
        }
        ++i;  // '}' or ']'
        stack.pop_back();
      }
    }
    begin_item();
  }
}

/// A value as a message quotes it: scalars as JSON, containers by kind.
std::string describe(const ordered_json& value) {
  if (value.is_object()) return value.empty() ? "an empty object" : "an object";
  if (value.is_array()) return value.empty() ? "an empty array" : "an array";
  std::string text = value.dump(-1, ' ', false, ordered_json::error_handler_t::replace);
  constexpr size_t kMax = 60;
  if (text.size() > kMax) {
    size_t cut = kMax;
    while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;  // UTF-8
    text = text.substr(0, cut) + (value.is_string() ? "...\"" : "...");
  }
  return text;
}

std::string json_quoted(std::string_view s) {
  return ordered_json(s).dump(-1, ' ', false, ordered_json::error_handler_t::replace);
}

/// The byte offset where nlohmann stops with an error other than a parse_error (a number beyond
/// double range): such exceptions carry no position, the SAX interface does.
class ErrorPosition : public nlohmann::json_sax<ordered_json> {
 public:
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t position, const std::string&,
                   const nlohmann::detail::exception&) override {
    position_ = position;
    return false;
  }
  static size_t of(std::string_view text) {
    ErrorPosition handler;
    ordered_json::sax_parse(text.begin(), text.end(), &handler);
    return handler.position_;
  }

 private:
  size_t position_ = 0;
};

/// An error nlohmann reports while parsing, as an InputError with the line and column of the
/// byte where parsing stopped (`position`: 1-based, as nlohmann counts).
InputError json_error(std::string_view text, const std::string& file, size_t position,
                      const std::string& what) {
  const size_t offset = std::min<size_t>(position > 0 ? position - 1 : 0, text.size());
  const size_t line_start = text.substr(0, offset).rfind('\n');
  const size_t column = line_start == std::string_view::npos ? offset + 1 : offset - line_start;
  // what() is "[json.exception.parse_error.101] parse error at line 2, column 3: DETAIL" or
  // "[json.exception.out_of_range.406] DETAIL".
  std::string detail = what;
  const size_t at_column = detail.find(", column ");
  const size_t start =
      at_column != std::string::npos ? detail.find(": ", at_column) + 2 : detail.find("] ") + 2;
  if (start >= 2 && start <= detail.size()) detail = detail.substr(start);
  return InputError(file, line_at(text, offset),
                    "invalid JSON at column " + std::to_string(column) + ": " + detail);
}

constexpr std::string_view kObjectKeys[] = {"name", "self", "sequence", "against",
                                            "role", "weld", "group",    "ignore"};

/// Validates a parsed scene document; every message names the key path and its line.
class SceneValidator {
 public:
  SceneValidator(std::string_view text, const std::string& file)
      : file_(file), positions_(text, file), base_(fs::path(file).parent_path()) {}

  Scene scene(const ordered_json& doc) const;

 private:
  [[noreturn]] void fail(const std::string& path, const std::string& what,
                         bool at_key = false) const {
    throw InputError(file_, positions_.line(path, at_key),
                     path.empty() ? what : path + ": " + what);
  }
  std::string non_empty_string(const ordered_json& object, const std::string& path, const char* key,
                               const char* what) const;
  ObjectSpec object(const ordered_json& o, const std::string& path) const;
  IgnoreRule ignore_rule(const ordered_json& rule, const std::string& path) const;

  const std::string& file_;
  Positions positions_;
  fs::path base_;  // the scene file's directory, for relative sequences
};

std::string SceneValidator::non_empty_string(const ordered_json& object, const std::string& path,
                                             const char* key, const char* what) const {
  const ordered_json& value = object.at(key);
  if (!value.is_string() || value.get_ref<const std::string&>().empty()) {
    fail(member_path(path, key), std::string("expected ") + what + ", got " + describe(value));
  }
  return value.get<std::string>();
}

IgnoreRule SceneValidator::ignore_rule(const ordered_json& rule, const std::string& path) const {
  if (!rule.is_array() || rule.size() != 2) {
    fail(path, "expected a pair of group names [\"a\", \"b\"] (\"*\" for any group), got " +
                   describe(rule));
  }
  std::string names[2];
  for (size_t k = 0; k < 2; ++k) {
    if (!rule[k].is_string() || rule[k].get_ref<const std::string&>().empty()) {
      fail(element_path(path, k),
           "expected a group name (a non-empty string, \"*\" for any "
           "group), got " +
               describe(rule[k]));
    }
    names[k] = rule[k].get<std::string>();
  }
  return {names[0], names[1]};
}

ObjectSpec SceneValidator::object(const ordered_json& o, const std::string& path) const {
  if (!o.is_object()) fail(path, "expected an object, got " + describe(o));
  for (auto it = o.begin(); it != o.end(); ++it) {
    if (std::find(std::begin(kObjectKeys), std::end(kObjectKeys), it.key()) ==
        std::end(kObjectKeys)) {
      fail(member_path(path, it.key()),
           "unknown key (an object has \"name\", \"sequence\", \"role\", \"group\", \"self\", "
           "\"against\", \"weld\" and \"ignore\")",
           true);
    }
  }
  for (const char* key : {"name", "sequence"}) {
    if (!o.contains(key)) fail(path, std::string("missing key \"") + key + "\"");
  }
  ObjectSpec spec;
  spec.name = non_empty_string(o, path, "name", "a non-empty string");
  spec.sequence = non_empty_string(o, path, "sequence", "a non-empty string (a SEQUENCE)");
  if (fs::path(spec.sequence).is_relative() && !base_.empty()) {
    spec.sequence = (base_ / spec.sequence).string();
  }
  if (o.contains("role")) {
    const ordered_json& role = o.at("role");
    if (role == "cloth") {
      spec.role = Role::cloth;
    } else if (role == "obstacle") {
      spec.role = Role::obstacle;
    } else {
      fail(member_path(path, "role"), "expected \"cloth\" or \"obstacle\", got " + describe(role));
    }
  }
  if (o.contains("group")) {
    spec.group = non_empty_string(o, path, "group", "a group name (a non-empty string)");
  }
  spec.self = spec.role == Role::cloth;
  if (o.contains("self")) {
    const ordered_json& self = o.at("self");
    if (!self.is_boolean()) {
      fail(member_path(path, "self"), "expected true or false, got " + describe(self));
    }
    spec.self = self.get<bool>();
  }
  if (o.contains("against")) {
    const ordered_json& against = o.at("against");
    const std::string against_path = member_path(path, "against");
    if (!against.is_array()) {
      fail(against_path, "expected an array of object names, got " + describe(against));
    }
    for (size_t k = 0; k < against.size(); ++k) {
      if (!against[k].is_string()) {
        fail(element_path(against_path, k),
             "expected an object name (a string), got " + describe(against[k]));
      }
      spec.against.push_back(against[k].get<std::string>());
    }
  }
  if (o.contains("weld")) {
    const ordered_json& weld = o.at("weld");
    if (!weld.is_number() || !std::isfinite(weld.get<double>()) || weld.get<double>() < 0) {
      fail(member_path(path, "weld"), "expected a number >= 0, got " + describe(weld));
    }
    spec.weld = weld.get<double>();
  }
  if (o.contains("ignore")) {
    const ordered_json& ignore = o.at("ignore");
    const std::string ignore_path = member_path(path, "ignore");
    if (!ignore.is_array()) {
      fail(ignore_path,
           "expected an array of group-name pairs [[\"a\", \"b\"], ...], got " + describe(ignore));
    }
    for (size_t k = 0; k < ignore.size(); ++k) {
      spec.ignore.push_back(ignore_rule(ignore[k], element_path(ignore_path, k)));
    }
  }
  return spec;
}

Scene SceneValidator::scene(const ordered_json& doc) const {
  if (!doc.is_object()) {
    fail("", "expected an object {\"objects\": [...]} at the top level, got " + describe(doc));
  }
  // The schema first: another schema's keys are not this one's to judge.
  if (doc.contains("schema")) {
    const ordered_json& schema = doc.at("schema");
    if (!schema.is_string() || schema.get_ref<const std::string&>() != kSchema) {
      fail("schema", "expected " + json_quoted(kSchema) + ", got " + describe(schema));
    }
  }
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    if (it.key() != "schema" && it.key() != "objects") {
      fail(it.key(), "unknown key (the top level has \"schema\" and \"objects\")", true);
    }
  }
  if (!doc.contains("objects")) fail("", "missing key \"objects\"");
  const ordered_json& objects = doc.at("objects");
  if (!objects.is_array() || objects.empty()) {
    fail("objects", "expected a non-empty array, got " + describe(objects));
  }

  Scene scene;
  std::map<std::string, size_t> index_of;
  for (size_t i = 0; i < objects.size(); ++i) {
    const std::string path = element_path("objects", i);
    scene.objects.push_back(object(objects[i], path));
    const auto [it, inserted] = index_of.emplace(scene.objects.back().name, i);
    if (!inserted) {
      fail(member_path(path, "name"), json_quoted(it->first) + " is already the name of " +
                                          element_path("objects", it->second));
    }
  }
  if (std::none_of(scene.objects.begin(), scene.objects.end(),
                   [](const ObjectSpec& o) { return o.role == Role::cloth; })) {
    fail("objects", "no object has role \"cloth\" (a scene checks at least one cloth)");
  }

  for (size_t i = 0; i < objects.size(); ++i) {
    ObjectSpec& spec = scene.objects[i];
    const std::string against_path = member_path(element_path("objects", i), "against");
    if (!objects[i].contains("against")) {
      if (spec.role == Role::cloth) {
        for (const ObjectSpec& other : scene.objects) {
          if (other.role == Role::obstacle) spec.against.push_back(other.name);
        }
      }
      continue;
    }
    for (size_t k = 0; k < spec.against.size(); ++k) {
      const std::string& name = spec.against[k];
      const std::string path = element_path(against_path, k);
      if (!index_of.contains(name)) fail(path, "no object named " + json_quoted(name));
      if (name == spec.name) {
        fail(path,
             "an object is not checked against itself through \"against\" (use \"self\": "
             "true)");
      }
      const auto first = std::find(spec.against.begin(), spec.against.begin() + k, name);
      if (first != spec.against.begin() + k) {
        fail(path, json_quoted(name) + " is already listed at " +
                       element_path("against", first - spec.against.begin()));
      }
    }
  }
  return scene;
}

/// `text` less frame tokens (%d, %04d, #..., @..., $F, $F4), glob characters and bracket
/// expressions, then trailing separators and frame digits, then leading separators.
std::string name_part(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '%') {
      size_t j = i + 1;
      while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) ++j;
      if (j < text.size() && text[j] == 'd') {
        i = j;
        continue;
      }
    } else if (c == '$' && i + 1 < text.size() && text[i + 1] == 'F') {
      i += 1;
      while (i + 1 < text.size() && std::isdigit(static_cast<unsigned char>(text[i + 1]))) ++i;
      continue;
    } else if (c == '[') {
      const size_t close = text.find(']', i + 2);  // "[]...]" holds a literal ']'
      if (close != std::string::npos) {
        i = close;
        continue;
      }
    } else if (c == '#' || c == '@' || c == '*' || c == '?') {
      continue;
    }
    out.push_back(c);
  }
  auto is_separator = [](char c) { return c == '.' || c == '_' || c == '-' || c == ' '; };
  for (bool changed = true; changed;) {
    changed = false;
    while (!out.empty() && is_separator(out.back())) {
      out.pop_back();
      changed = true;
    }
    size_t digits = 0;
    while (digits < out.size() &&
           std::isdigit(static_cast<unsigned char>(out[out.size() - 1 - digits]))) {
      ++digits;
    }
    const bool after_separator = digits < out.size() && is_separator(out[out.size() - 1 - digits]);
    if (digits > 0 && (digits >= 3 || digits == out.size() || after_separator)) {
      out.resize(out.size() - digits);
      changed = true;
    }
  }
  const size_t first = std::find_if_not(out.begin(), out.end(), is_separator) - out.begin();
  return out.substr(first);
}

std::string name_from_sequence(const std::string& sequence) {
  const fs::path path(sequence);
  if (path.has_filename()) {
    const std::string name = name_part(path.stem().string());
    if (!name.empty()) return name;
  }
  const std::string dir = name_part(path.parent_path().filename().string());
  return dir.empty() ? "obstacle" : dir;
}

}  // namespace

std::vector<std::pair<int, int>> Scene::cross_checks() const {
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < objects.size(); ++i) {
    for (const std::string& name : objects[i].against) {
      int found = -1;
      for (size_t j = 0; j < objects.size(); ++j) {
        if (objects[j].name != name) continue;
        if (found >= 0 || j == i) {
          throw InternalError("scene: " + objects[i].name + " is checked against " +
                              json_quoted(name) + ", which is not exactly one other object's name");
        }
        found = static_cast<int>(j);
      }
      if (found < 0) {
        throw InternalError("scene: " + objects[i].name + " is checked against " +
                            json_quoted(name) + ", which no object is named");
      }
      const int a = static_cast<int>(i);
      pairs.emplace_back(std::min(a, found), std::max(a, found));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

std::vector<int> Scene::self_checks() const {
  std::vector<int> out;
  for (size_t i = 0; i < objects.size(); ++i) {
    if (objects[i].self) out.push_back(static_cast<int>(i));
  }
  return out;
}

Scene parse_scene(std::string_view text, const std::string& path) {
  ordered_json doc;
  try {
    doc = ordered_json::parse(text.data(), text.data() + text.size());
  } catch (const ordered_json::parse_error& e) {
    throw json_error(text, path, e.byte, e.what());
  } catch (const ordered_json::exception& e) {
    throw json_error(text, path, ErrorPosition::of(text), e.what());
  }
  return SceneValidator(text, path).scene(doc);
}

Scene read_scene_file(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path, 0, "cannot read: a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path, 0, std::string("cannot read: ") + std::strerror(errno));
  return parse_scene(text.str(), path);
}

Scene scene_from_flags(const std::string& cloth_sequence,
                       const std::vector<std::string>& obstacle_sequences,
                       std::optional<double> weld) {
  Scene scene;
  ObjectSpec cloth;
  cloth.name = "cloth";
  cloth.sequence = cloth_sequence;
  cloth.weld = weld;
  scene.objects.push_back(cloth);
  std::set<std::string> taken = {"cloth"};
  for (const std::string& sequence : obstacle_sequences) {
    const std::string stem = name_from_sequence(sequence);
    std::string name = stem;
    for (int suffix = 2; taken.contains(name); ++suffix) name = stem + "-" + std::to_string(suffix);
    taken.insert(name);
    ObjectSpec obstacle;
    obstacle.name = name;
    obstacle.sequence = sequence;
    obstacle.role = Role::obstacle;
    obstacle.self = false;
    obstacle.weld = weld;
    scene.objects.push_back(obstacle);
    scene.objects.front().against.push_back(name);
  }
  return scene;
}

}  // namespace snag::scene
