#include "ecs/config.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace monolith {

namespace {
std::string joinMessage(const std::string& file, const std::string& path, const std::string& expected,
                        const std::string& got) {
  std::string m = file.empty() ? std::string("<scene>") : file;
  m += ": ";
  m += path.empty() ? std::string("(top level)") : path;
  m += ": expected " + expected;
  if (!got.empty()) m += ", got " + got;
  return m;
}

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string boundText(Bound b) {
  switch (b) {
    case Bound::Positive: return "a positive finite number";
    case Bound::NonNegative: return "a non-negative finite number";
    case Bound::Any: break;
  }
  return "a finite number";
}
// Reports a missing required key. When the object holds an unknown key that is a near miss of
// it ("mas" for "mass"), that typo is the actual mistake: name it, not the missing key.
[[noreturn]] void failMissing(const Config& c, const std::set<std::string>& used, const std::string& key,
                              const std::string& expected) {
  for (const auto& k : c.keys())
    if (k != key && !used.count(k) && closestMatch(k, {key}) == key)
      throw SceneError(c.file(), c.pathOf(k), "no key \"" + k + "\" here (unknown key; did you mean \"" + key + "\"?)",
                       "");
  c.failAt(key, expected + " (required key is missing)", "");
}
}  // namespace

SceneError::SceneError(std::string file, std::string path, std::string expected, std::string got)
    : std::runtime_error(joinMessage(file, path, expected, got)),
      file_(std::move(file)), path_(std::move(path)), expected_(std::move(expected)), got_(std::move(got)) {}

std::string describeJson(const Json& j) {
  switch (j.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::boolean: return j.get<bool>() ? "true" : "false";
    case Json::value_t::string: {
      std::string s = j.dump();
      return "the string " + (s.size() > 40 ? s.substr(0, 37) + "...\"" : s);
    }
    case Json::value_t::array: return "an array of " + std::to_string(j.size()) + " element" + (j.size() == 1 ? "" : "s");
    case Json::value_t::object: return "an object";
    case Json::value_t::number_float: {
      const double v = j.get<double>();
      if (std::isnan(v)) return "NaN";
      if (std::isinf(v)) return v > 0 ? "inf (number too large)" : "-inf (number too large)";
      return j.dump();
    }
    default: return j.dump();
  }
}

std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t bestDistance = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const auto& c : candidates) {
    const std::size_t dist = editDistance(word, c);
    if (dist < bestDistance) {
      bestDistance = dist;
      best = c;
    }
  }
  return best;
}

Config::Config(const Json& node, std::string file, std::string path)
    : node_(&node), file_(std::move(file)), path_(std::move(path)), used_(std::make_shared<std::set<std::string>>()) {}

std::string Config::pathOf(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

void Config::fail(const std::string& expected, const std::string& got) const {
  throw SceneError(file_, path_, expected, got);
}
void Config::failAt(const std::string& key, const std::string& expected, const std::string& got) const {
  throw SceneError(file_, pathOf(key), expected, got);
}

bool Config::has(const std::string& key) const { return node_->is_object() && node_->contains(key); }

Config Config::child(const std::string& key) const {
  if (!node_->is_object()) fail("an object", describeJson(*node_));
  if (!node_->contains(key)) failMissing(*this, *used_, key, "an object");
  used_->insert(key);
  const Json& c = (*node_)[key];
  if (!c.is_object()) failAt(key, "an object", describeJson(c));
  return Config(c, file_, pathOf(key));
}

Config Config::element(std::size_t i) const {
  return Config((*node_)[i], file_, path_ + "[" + std::to_string(i) + "]");
}

std::size_t Config::arraySize() const {
  if (!node_->is_array()) fail("an array", describeJson(*node_));
  return node_->size();
}

std::vector<std::string> Config::keys() const {
  std::vector<std::string> k;
  if (node_->is_object())
    for (auto it = node_->begin(); it != node_->end(); ++it) k.push_back(it.key());
  return k;
}

double Config::checkedNumber(const std::string& key, const Json& v, Bound bound) const {
  if (!v.is_number()) failAt(key, boundText(bound), describeJson(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) failAt(key, boundText(bound), describeJson(v));
  if (bound == Bound::Positive && !(x > 0)) failAt(key, boundText(bound), describeJson(v));
  if (bound == Bound::NonNegative && !(x >= 0)) failAt(key, boundText(bound), describeJson(v));
  return x;
}

double Config::number(const std::string& key, Bound bound) const {
  if (!has(key)) failMissing(*this, *used_, key, boundText(bound));
  used_->insert(key);
  return checkedNumber(key, (*node_)[key], bound);
}

double Config::number(const std::string& key, double fallback, Bound bound) const {
  used_->insert(key);  // known key, even when absent: feeds "did you mean"
  return has(key) ? number(key, bound) : fallback;
}

long Config::integer(const std::string& key, long min, long max) const {
  const std::string expected = "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  if (!has(key)) failMissing(*this, *used_, key, expected);
  used_->insert(key);
  const Json& v = (*node_)[key];
  if (!v.is_number_integer()) {
    if (v.is_number_float() && std::isfinite(v.get<double>()) && v.get<double>() == std::floor(v.get<double>()) &&
        std::abs(v.get<double>()) < 9e15) {
      const long x = static_cast<long>(v.get<double>());
      if (x >= min && x <= max) return x;
    }
    failAt(key, expected, describeJson(v));
  }
  const long x = v.get<long>();
  if (x < min || x > max) failAt(key, expected, describeJson(v));
  return x;
}

long Config::integer(const std::string& key, long fallback, long min, long max) const {
  used_->insert(key);
  return has(key) ? integer(key, min, max) : fallback;
}

bool Config::boolean(const std::string& key, bool fallback) const {
  used_->insert(key);
  if (!has(key)) return fallback;
  const Json& v = (*node_)[key];
  if (!v.is_boolean()) failAt(key, "true or false", describeJson(v));
  return v.get<bool>();
}

std::string Config::string(const std::string& key) const {
  if (!has(key)) failMissing(*this, *used_, key, "a string");
  used_->insert(key);
  const Json& v = (*node_)[key];
  if (!v.is_string()) failAt(key, "a string", describeJson(v));
  return v.get<std::string>();
}

std::string Config::string(const std::string& key, const std::string& fallback) const {
  used_->insert(key);
  return has(key) ? string(key) : fallback;
}

std::string Config::oneOf(const std::string& key, const std::vector<std::string>& allowed,
                          const std::string& fallback) const {
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "\"" : ", \"") + a + "\"";
  used_->insert(key);
  if (!has(key)) {
    if (fallback.empty()) failMissing(*this, *used_, key, "one of " + list);
    return fallback;
  }
  used_->insert(key);
  const Json& v = (*node_)[key];
  if (!v.is_string()) failAt(key, "one of " + list, describeJson(v));
  const std::string s = v.get<std::string>();
  if (std::find(allowed.begin(), allowed.end(), s) == allowed.end()) {
    const std::string guess = closestMatch(s, allowed);
    failAt(key, "one of " + list, describeJson(v) + (guess.empty() ? "" : " (did you mean \"" + guess + "\"?)"));
  }
  return s;
}

Eigen::VectorXd Config::vector(const std::string& key, int size, Bound bound) const {
  const std::string expected = "an array of " + std::to_string(size) + " finite numbers" +
                               (bound == Bound::Positive ? " > 0" : bound == Bound::NonNegative ? " >= 0" : "");
  if (!has(key)) failMissing(*this, *used_, key, expected);
  used_->insert(key);
  const Json& v = (*node_)[key];
  if (!v.is_array() || static_cast<int>(v.size()) != size) failAt(key, expected, describeJson(v));
  Eigen::VectorXd out(size);
  for (int i = 0; i < size; ++i) {
    const Json& e = v[i];
    const std::string at = key + "[" + std::to_string(i) + "]";
    if (!e.is_number() || !std::isfinite(e.get<double>())) failAt(at, expected, describeJson(e));
    out[i] = e.get<double>();
    if ((bound == Bound::Positive && !(out[i] > 0)) || (bound == Bound::NonNegative && !(out[i] >= 0)))
      failAt(at, expected, describeJson(e));
  }
  return out;
}

Eigen::VectorXd Config::vector(const std::string& key, const Eigen::VectorXd& fallback, Bound bound) const {
  used_->insert(key);
  return has(key) ? vector(key, static_cast<int>(fallback.size()), bound) : fallback;
}

Eigen::MatrixXd Config::matrix(const std::string& key, int rows, int cols) const {
  const std::string expected = "an array of " + std::to_string(rows) + " rows of " + std::to_string(cols) + " finite numbers";
  if (!has(key)) failMissing(*this, *used_, key, expected);
  used_->insert(key);
  const Json& v = (*node_)[key];
  if (!v.is_array() || static_cast<int>(v.size()) != rows) failAt(key, expected, describeJson(v));
  Eigen::MatrixXd m(rows, cols);
  for (int r = 0; r < rows; ++r) {
    const Json& row = v[r];
    const std::string at = key + "[" + std::to_string(r) + "]";
    if (!row.is_array() || static_cast<int>(row.size()) != cols) failAt(at, expected, describeJson(row));
    for (int c = 0; c < cols; ++c) {
      if (!row[c].is_number() || !std::isfinite(row[c].get<double>()))
        failAt(at + "[" + std::to_string(c) + "]", "a finite number", describeJson(row[c]));
      m(r, c) = row[c].get<double>();
    }
  }
  return m;
}

void Config::finish() const {
  if (!node_->is_object()) return;
  std::vector<std::string> known(used_->begin(), used_->end());
  for (auto it = node_->begin(); it != node_->end(); ++it) {
    if (used_->count(it.key())) continue;
    const std::string guess = closestMatch(it.key(), known);
    std::string expected = "no key \"" + it.key() + "\" here (unknown key";
    expected += guess.empty() ? ")" : "; did you mean \"" + guess + "\"?)";
    throw SceneError(file_, pathOf(it.key()), expected, "");
  }
}

}  // namespace monolith
