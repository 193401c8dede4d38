#pragma once
// FunctionStage: a Stage<T> made from a name and a callable `Status(T&, const FrameStamps&)`, for
// stages that are a single function (tests, adapters) and need no class of their own.
//
//   auto scale = makeFunctionStage<Frame>("scale", [](Frame& f, const FrameStamps&) {
//     f.value *= 2;
//     return Status::Ok();
//   });
#include <type_traits>
#include <utility>

#include "runtime/stage.h"

namespace plumb::runtime {

template <typename T, typename Fn>
class FunctionStage final : public Stage<T> {
 public:
  FunctionStage(const char* name, Fn fn) : name_(name), fn_(std::move(fn)) {}
  const char* name() const override { return name_; }
  Status process(T& payload, const FrameStamps& stamps) override { return fn_(payload, stamps); }

 private:
  const char* name_;  // must outlive the stage (a string literal)
  Fn fn_;
};

template <typename T, typename Fn>
FunctionStage<T, std::decay_t<Fn>> makeFunctionStage(const char* name, Fn&& fn) {
  return FunctionStage<T, std::decay_t<Fn>>(name, std::forward<Fn>(fn));
}

}  // namespace plumb::runtime
