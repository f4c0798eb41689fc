#pragma once
// One value of a type its holder does not name: what lets a config struct carry the block of
// keys a part registered apart owns (a camera's backend, capture/camera_backend.h) without a
// field of its own for each. Copyable and comparable like the struct it is part of; the block's
// type T is default-constructible and has operator==.
#include <memory>
#include <typeinfo>
#include <utility>

namespace ss {

class AnyBlock {
 public:
  AnyBlock() = default;
  AnyBlock(const AnyBlock& other) : held_(other.held_ ? other.held_->Clone() : nullptr) {}
  AnyBlock& operator=(const AnyBlock& other) {
    if (this != &other) held_ = other.held_ ? other.held_->Clone() : nullptr;
    return *this;
  }
  AnyBlock(AnyBlock&&) noexcept = default;
  AnyBlock& operator=(AnyBlock&&) noexcept = default;
  ~AnyBlock() = default;
  // A block holding `value`.
  template <typename T>
  static AnyBlock Of(T value) {
    AnyBlock block;
    block.Use<T>() = std::move(value);
    return block;
  }
  [[nodiscard]] bool empty() const { return held_ == nullptr; }

  // The T held, made first (default values) when it holds none or one of another type. The
  // reference stays valid until the block is assigned or another type is used.
  template <typename T>
  T& Use() {
    if (T* held = Find<T>()) return *held;
    auto made = std::make_unique<Held<T>>();
    T& value = made->value;
    held_ = std::move(made);
    return value;
  }
  // The T held; nullptr when it holds none or one of another type.
  template <typename T>
  T* Find() {
    return held_ && held_->Type() == typeid(T) ? &static_cast<Held<T>&>(*held_).value : nullptr;
  }
  template <typename T>
  const T* Find() const {
    return held_ && held_->Type() == typeid(T) ? &static_cast<const Held<T>&>(*held_).value
                                               : nullptr;
  }
  // The T held, or T's defaults when it holds none.
  template <typename T>
  const T& Get() const {
    static const T kDefaults{};
    const T* held = Find<T>();
    return held != nullptr ? *held : kDefaults;
  }

  // Equal when both hold nothing, or values of one type that compare equal.
  bool operator==(const AnyBlock& other) const {
    if (!held_ || !other.held_) return !held_ && !other.held_;
    return held_->Type() == other.held_->Type() && held_->Equals(*other.held_);
  }

 private:
  struct Base {
    virtual ~Base() = default;
    [[nodiscard]] virtual std::unique_ptr<Base> Clone() const = 0;
    [[nodiscard]] virtual bool Equals(const Base& other) const = 0;  // other of the same Type()
    [[nodiscard]] virtual const std::type_info& Type() const = 0;
  };
  template <typename T>
  struct Held final : Base {
    T value{};
    [[nodiscard]] std::unique_ptr<Base> Clone() const override {
      return std::make_unique<Held>(*this);
    }
    [[nodiscard]] bool Equals(const Base& other) const override {
      return value == static_cast<const Held&>(other).value;
    }
    [[nodiscard]] const std::type_info& Type() const override { return typeid(T); }
  };
  std::unique_ptr<Base> held_;
};

}  // namespace ss
