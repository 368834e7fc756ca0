#pragma once
// A non-owning reference to a callable: what std::function does for a callback that is only called while the
// caller's callable is alive, without its allocation, copy and double indirection. The inner loops (a random
// number per walk step, a shadow ray per MNEE solution) call through it.
//
// It refers to the callable it was built from, which must outlive it: bind it to a named lambda or pass a
// temporary straight to a parameter, never store one built from a temporary.
#include <memory>
#include <type_traits>
#include <utility>

namespace eyelib {

template <class Signature> class FunctionRef;

template <class R, class... Args> class FunctionRef<R(Args...)> {
 public:
  /// Empty: not callable (operator bool is false).
  FunctionRef() = default;

  template <class F, class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, FunctionRef> &&
                                              std::is_invocable_r_v<R, F&, Args...>>>
  FunctionRef(F&& f) noexcept  // NOLINT: implicit, like std::function's
      : object_(const_cast<void*>(static_cast<const void*>(std::addressof(f)))),
        call_([](void* object, Args... args) -> R {
          return (*static_cast<std::remove_reference_t<F>*>(object))(std::forward<Args>(args)...);
        }) {}

  R operator()(Args... args) const { return call_(object_, std::forward<Args>(args)...); }
  explicit operator bool() const { return call_ != nullptr; }

 private:
  void* object_ = nullptr;
  R (*call_)(void*, Args...) = nullptr;
};

}  // namespace eyelib
