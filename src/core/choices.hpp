// A typed registry of named choices: the one place where the words a user may write for a
// setting (a config key such as run.event_queue or potential[].kind) meet the enum the code
// switches on, with one doc line per choice.
//
//   enum class EventQueue { kCalendar, kHeap, kTree };
//   inline constexpr ChoiceEntry<EventQueue> kEventQueueEntries[] = {
//       {"calendar", EventQueue::kCalendar, "calendar queue (the default)"}, ...};
//   inline constexpr Choices<EventQueue> kEventQueues{"event queue", kEventQueueEntries};
//
// The config reader validates names through it (its error lists the names), to_toml writes the
// names, docs/config.md lists them, and the factories turn a name into the enum with at(),
// which throws InputError for a name that is not registered (a config built in code).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/error.hpp"

namespace kairos {

template <class E>
struct ChoiceEntry {
  std::string_view name;
  E value;
  std::string_view doc;  // one line, for docs/config.md and `kairos config-keys`
};

template <class E>
class Choices {
 public:
  constexpr Choices(std::string_view what, std::span<const ChoiceEntry<E>> entries)
      : what_(what), entries_(entries) {}

  std::string_view what() const { return what_; }
  std::span<const ChoiceEntry<E>> entries() const { return entries_; }

  const ChoiceEntry<E>* find(std::string_view name) const {
    for (const ChoiceEntry<E>& e : entries_)
      if (e.name == name) return &e;
    return nullptr;
  }
  bool contains(std::string_view name) const { return find(name) != nullptr; }
  // Whether `name` is registered as `value`: kinds.is(spec.kind, PotentialKind::kWca).
  bool is(std::string_view name, E value) const {
    const ChoiceEntry<E>* e = find(name);
    return e != nullptr && e->value == value;
  }

  // The enum of a registered name; InputError "unknown WHAT 'NAME' (a, b or c)" otherwise.
  E at(std::string_view name) const {
    if (const ChoiceEntry<E>* e = find(name)) return e->value;
    throw InputError("unknown " + std::string(what_) + " '" + std::string(name) + "' (" +
                     names(", ", " or ") + ")");
  }

  std::string_view name(E value) const {
    for (const ChoiceEntry<E>& e : entries_)
      if (e.value == value) return e.name;
    return {};
  }

  // "a, b, c" (last_separator between the last two).
  std::string names(std::string_view separator = ", ",
                    std::optional<std::string_view> last_separator = std::nullopt) const {
    std::string out;
    for (std::size_t i = 0; i < entries_.size(); ++i) {
      if (i > 0) out += i + 1 == entries_.size() && last_separator ? *last_separator : separator;
      out += entries_[i].name;
    }
    return out;
  }

 private:
  std::string_view what_;
  std::span<const ChoiceEntry<E>> entries_;
};

}  // namespace kairos
