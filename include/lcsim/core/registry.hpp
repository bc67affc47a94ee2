// The one registry of named methods: LCP solvers, impact laws and
// integrators are each chosen by name from a Registry<Interface>.
//
// A layer's registry holds its own methods from the start (the layer's
// accessor, as lcp::solvers(), is Registry::instance with a fill function that
// adds them when it is first used); an optional component (lcsim::bullet,
// lcsim::ipopt) adds its methods with a namespace-scope Registrar in a source
// file that CMake links into every program that links the component, so no
// caller ever makes a registration call. Thread-safe.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace lcsim {

template <class Interface>
class Registry {
 public:
  using Factory = std::function<std::unique_ptr<Interface>()>;

  // `kind` names the methods in messages ("LCP solver", "impact law", "method").
  explicit Registry(std::string kind) : kind_(std::move(kind)) {}

  // The one registry of Interface's methods: made on the first call, when
  // `fill` adds the layer's own methods, and the same one on every later call
  // (thread-safe). Never destroyed: a component's Registrar adds to it before
  // main, and code run at exit may still look a name up. A layer's accessor
  // (lcp::solvers(), impact::laws(), sim::integrators()) is its only caller.
  static Registry& instance(const char* kind, void (*fill)(Registry&)) {
    static Registry& r = *[&] {
      auto* reg = new Registry(kind);
      fill(*reg);
      return reg;
    }();
    return r;
  }

  // Adds `name`, or replaces the factory of a name already present (the
  // position in names() is kept).
  void add(std::string name, Factory factory) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [n, f] : entries_)
      if (n == name) {
        f = std::move(factory);
        return;
      }
    entries_.emplace_back(std::move(name), std::move(factory));
  }

  // `alias` stands for the method `target` in contains() and make() (an old
  // name kept working); names() does not list it, and alias_note(alias)
  // says what it now means.
  void add_alias(std::string alias, std::string target, std::string note) {
    std::lock_guard<std::mutex> lock(mutex_);
    aliases_.push_back({std::move(alias), std::move(target), std::move(note)});
  }

  // The note of an alias ("" for a name that is not one).
  std::string alias_note(std::string_view name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& a : aliases_)
      if (a.alias == name) return a.note;
    return "";
  }

  bool contains(std::string_view name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return find(name) != nullptr;
  }

  // A new instance of `name` (or of the method an alias stands for); nullptr
  // when unknown (unknown_message says why).
  std::unique_ptr<Interface> make(std::string_view name) const {
    Factory f;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (const Factory* p = find(name)) f = *p;
    }
    return f ? f() : nullptr;
  }

  // make(name), or std::invalid_argument with unknown_message(name, hint).
  std::unique_ptr<Interface> make_or_throw(std::string_view name,
                                           std::string_view hint = {}) const {
    if (auto m = make(name)) return m;
    throw std::invalid_argument(unknown_message(name, hint));
  }

  // The names, in registration order.
  std::vector<std::string> names() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<std::string> out;
    for (const auto& e : entries_) out.push_back(e.first);
    return out;
  }

  // "unknown <kind> 'x' (known: a, b, c; alias d)", plus `hint` when given.
  std::string unknown_message(std::string_view name, std::string_view hint = {}) const {
    std::string known;
    for (const auto& n : names()) known += (known.empty() ? "" : ", ") + n;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (size_t i = 0; i < aliases_.size(); ++i)
        known += (i ? ", " : (aliases_.size() > 1 ? "; aliases " : "; alias ")) + aliases_[i].alias;
    }
    std::string msg = "unknown " + kind_ + " '" + std::string(name) + "' (known: " + known + ")";
    if (!hint.empty()) msg += "; " + std::string(hint);
    return msg;
  }

  const std::string& kind() const { return kind_; }

 private:
  struct Alias {
    std::string alias, target, note;
  };
  // The factory of `name` or of the target of alias `name`; mutex_ held.
  const Factory* find(std::string_view name) const {
    for (const auto& e : entries_)
      if (e.first == name) return &e.second;
    for (const auto& a : aliases_)
      if (a.alias == name)
        for (const auto& e : entries_)
          if (e.first == a.target) return &e.second;
    return nullptr;
  }

  std::string kind_;
  mutable std::mutex mutex_;
  std::vector<std::pair<std::string, Factory>> entries_;
  std::vector<Alias> aliases_;
};

// Adds a method to `registry` when the program starts: a namespace-scope
// object in a component's source file.
template <class Interface>
struct Registrar {
  Registrar(Registry<Interface>& registry, std::string name,
            typename Registry<Interface>::Factory factory) {
    registry.add(std::move(name), std::move(factory));
  }
};

}  // namespace lcsim
