#pragma once
// Reading YAML config files (jobs, training) with errors that name the file, the
// dotted field and what was expected, and with unknown keys rejected.

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "core/errors.h"

namespace handlabel {

// Walks one YAML mapping, remembering which keys were read so unknown ones are reported.
class Section {
 public:
  Section(const YAML::Node& node, std::string file, std::string prefix)
      : node_(node), file_(std::move(file)), prefix_(std::move(prefix)) {
    if (node_ && !node_.IsMap()) {
      throw InputError(file_, prefix_.empty() ? "(top level)" : prefix_, "a mapping");
    }
    if (prefix_.empty()) RejectDuplicateKeys(node_, prefix_);
  }

  template <typename T>
  void Read(const char* key, T* value) {
    seen_.insert(key);
    if (!node_ || !node_[key]) return;
    try {
      *value = node_[key].as<T>();
    } catch (const YAML::Exception&) {
      throw InputError(file_, Name(key), TypeName(value), "'" + Text(key) + "'");
    }
  }

  Section Child(const char* key) {
    seen_.insert(key);
    return Section(node_ ? node_[key] : YAML::Node(), file_, Name(key));
  }

  // The node under `key`, marked as read, for values the caller converts itself.
  YAML::Node Raw(const char* key) {
    seen_.insert(key);
    return node_ ? node_[key] : YAML::Node();
  }

  void RejectUnknownKeys() const {
    if (!node_) return;
    for (const auto& entry : node_) {
      const std::string key = entry.first.Scalar();  // scalar: checked on load
      if (!seen_.count(key)) {
        std::string known;
        for (const std::string& k : seen_) known += (known.empty() ? "" : ", ") + k;
        throw InputError(file_, Name(key.c_str()), "a known key (" + known + ")",
                         "unknown key");
      }
    }
  }

  std::string Name(const char* key) const {
    return prefix_.empty() ? key : prefix_ + "." + key;
  }

 private:
  // yaml-cpp keeps every entry of a mapping and lookups find the first, so a key
  // written twice would silently ignore the second value: refused in the whole tree.
  void RejectDuplicateKeys(const YAML::Node& node, const std::string& at) const {
    if (!node) return;
    if (node.IsSequence()) {
      for (size_t i = 0; i < node.size(); ++i) {
        RejectDuplicateKeys(node[i], at + "[" + std::to_string(i) + "]");
      }
    } else if (node.IsMap()) {
      std::set<std::string> keys;
      for (const auto& entry : node) {
        if (!entry.first.IsScalar()) {
          throw InputError(file_, at.empty() ? "(top level)" : at, "plain text keys",
                           "a list or mapping used as a key");
        }
        const std::string key = entry.first.Scalar();
        const std::string name = at.empty() ? key : at + "." + key;
        if (!keys.insert(key).second) {
          throw InputError(file_, name, "each key once per mapping", "a duplicate key");
        }
        RejectDuplicateKeys(entry.second, name);
      }
    }
  }

  std::string Text(const char* key) const {
    YAML::Emitter out;
    out << node_[key];
    return out.c_str();
  }
  static const char* TypeName(std::string*) { return "a string"; }
  static const char* TypeName(int*) { return "an integer"; }
  static const char* TypeName(uint64_t*) { return "a non-negative integer"; }
  static const char* TypeName(double*) { return "a number"; }
  static const char* TypeName(float*) { return "a number"; }
  static const char* TypeName(bool*) { return "true or false"; }
  template <typename T>
  static const char* TypeName(T*) {
    return "a value of the right type";
  }
  static const char* TypeName(std::vector<std::string>*) { return "a list of strings"; }

  YAML::Node node_;
  std::string file_;
  std::string prefix_;
  std::set<std::string> seen_;
};

}  // namespace handlabel
