#pragma once
// Located reading of JSON configs. Every value is read through a Config that knows the file
// and the JSON path it came from, so any problem is reported as
//   scene.json: entities[3].rigid_body.mass: expected a positive number, got -1
// and unknown keys are errors (with a "did you mean" suggestion) instead of being ignored.
#include <Eigen/Core>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace monolith {

using Json = nlohmann::json;

class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, std::string path, std::string expected, std::string got);
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  const std::string& expected() const { return expected_; }
  const std::string& got() const { return got_; }

 private:
  std::string file_, path_, expected_, got_;
};

// Short description of a JSON value for messages: `-1`, `"abc"`, `an array of 2 elements`, ...
std::string describeJson(const Json& j);
// Closest candidate within a small edit distance, or "".
std::string closestMatch(const std::string& word, const std::vector<std::string>& candidates);

enum class Bound { Any, Positive, NonNegative };

class Config {
 public:
  Config(const Json& node, std::string file, std::string path);

  const Json& raw() const { return *node_; }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  std::string pathOf(const std::string& key) const;

  [[noreturn]] void fail(const std::string& expected, const std::string& got) const;
  [[noreturn]] void failAt(const std::string& key, const std::string& expected, const std::string& got) const;

  bool has(const std::string& key) const;
  Config child(const std::string& key) const;  // must be present and an object
  Config element(std::size_t i) const;
  std::size_t arraySize() const;  // this node must be an array
  std::vector<std::string> keys() const;

  double number(const std::string& key, Bound bound = Bound::Any) const;
  double number(const std::string& key, double fallback, Bound bound = Bound::Any) const;
  long integer(const std::string& key, long min, long max) const;
  long integer(const std::string& key, long fallback, long min, long max) const;
  bool boolean(const std::string& key, bool fallback) const;
  std::string string(const std::string& key) const;
  std::string string(const std::string& key, const std::string& fallback) const;
  std::string oneOf(const std::string& key, const std::vector<std::string>& allowed, const std::string& fallback) const;
  Eigen::VectorXd vector(const std::string& key, int size, Bound bound = Bound::Any) const;
  Eigen::VectorXd vector(const std::string& key, const Eigen::VectorXd& fallback, Bound bound = Bound::Any) const;
  Eigen::MatrixXd matrix(const std::string& key, int rows, int cols) const;

  // Marks a key as consumed without reading it (read by someone else).
  void markUsed(const std::string& key) const { used_->insert(key); }
  // Unknown keys in this object are errors.
  void finish() const;

 private:
  double checkedNumber(const std::string& key, const Json& v, Bound bound) const;
  const Json* node_;
  std::string file_, path_;
  std::shared_ptr<std::set<std::string>> used_;
};

}  // namespace monolith
