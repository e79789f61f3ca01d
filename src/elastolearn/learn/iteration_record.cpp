#include <elastolearn/learn/iteration_record.hpp>

#include <stdexcept>
#include <utility>

namespace elastolearn::learn {

namespace {

constexpr std::pair<ForwardStatus, const char*> k_status_names[] = {
  { ForwardStatus::completed, "completed" },
  { ForwardStatus::diverged, "diverged" },
  { ForwardStatus::unstable, "unstable" },
};

} // namespace

std::string to_string(ForwardStatus status) {
  for (const auto& [s, name] : k_status_names)
    if (s == status)
      return name;
  throw std::logic_error("unknown ForwardStatus");
}

std::optional<ForwardStatus> forward_status_from_string(const std::string& name) {
  for (const auto& [s, n] : k_status_names)
    if (name == n)
      return s;
  return std::nullopt;
}

ForwardOutcome::ForwardOutcome(
    ForwardStatus status, const ErrorSummary& error, std::string message, double seconds)
    : m_status(status)
    , m_error(error)
    , m_message(std::move(message))
    , m_seconds(seconds) { }

ForwardOutcome ForwardOutcome::completed(const ErrorSummary& error, double seconds) {
  return { ForwardStatus::completed, error, {}, seconds };
}

ForwardOutcome ForwardOutcome::diverged(std::string message, double seconds) {
  return { ForwardStatus::diverged, {}, std::move(message), seconds };
}

ForwardOutcome ForwardOutcome::unstable(std::string message, double seconds) {
  return { ForwardStatus::unstable, {}, std::move(message), seconds };
}

const ErrorSummary& ForwardOutcome::error() const {
  if (!completed())
    throw std::logic_error(
        "ForwardOutcome::error: the simulation " + to_string(m_status) + " and has no error");
  return m_error;
}

int iteration_of(const IterationRecord& record) {
  return std::visit([](const auto& r) { return r.iteration; }, record);
}

const ForwardOutcome& forward_of(const IterationRecord& record) {
  return std::visit([](const auto& r) -> const ForwardOutcome& { return r.forward; }, record);
}

const SpaceTimeStages* stages_of(const IterationRecord& record) {
  const auto* loop = std::get_if<LoopRecord>(&record);
  return loop ? loop->stages() : nullptr;
}

const ForwardFitRecord* forward_fit_of(const IterationRecord& record) {
  return std::get_if<ForwardFitRecord>(&record);
}

double seconds_of(const IterationRecord& record) {
  const SpaceTimeStages* stages = stages_of(record);
  return forward_of(record).seconds() + (stages ? stages->seconds() : 0.0);
}

} // namespace elastolearn::learn
