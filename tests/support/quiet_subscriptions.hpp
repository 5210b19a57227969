#pragma once
// Typed LCM subscriptions for a test that also sends malformed messages on
// the channels it listens to. LCM's own typed subscriptions print
// "error -1 decoding T!!!" for each message they cannot decode: thousands
// of lines in a test whose failure message must still be read in CI's
// shortened output. These decode with decode_message (as the programs do)
// and count what they cannot decode instead of printing it.
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "tofguard/common/decode.hpp"

namespace tofguard::test {

class QuietSubscriptions {
 public:
  // Calls `on_message` for each message on `channel` that decodes as T;
  // counts the others. The subscription lives as long as this object.
  template <class T>
  void add(lcm::LCM& lcm, const std::string& channel, std::function<void(const T&)> on_message) {
    auto subscription = std::make_unique<Typed<T>>(std::move(on_message), &undecodable_);
    lcm.subscribe(channel, &Typed<T>::handle, subscription.get());
    subscriptions_.push_back(std::move(subscription));
  }

  // Messages received that did not decode as their channel's type.
  int64_t undecodable() const { return undecodable_; }

 private:
  struct Base {
    virtual ~Base() = default;
  };
  template <class T>
  struct Typed : Base {
    Typed(std::function<void(const T&)> on_message, int64_t* undecodable)
        : on_message(std::move(on_message)), undecodable(undecodable) {}
    void handle(const lcm::ReceiveBuffer* rbuf, const std::string&) {
      const std::optional<T> message = decode_message<T>(rbuf->data, static_cast<int>(rbuf->data_size));
      if (message) {
        on_message(*message);
      } else {
        ++*undecodable;
      }
    }
    std::function<void(const T&)> on_message;
    int64_t* undecodable;
  };
  std::vector<std::unique_ptr<Base>> subscriptions_;
  int64_t undecodable_ = 0;
};

}  // namespace tofguard::test
