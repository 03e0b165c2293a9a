#include "apps/studio/studio_board.h"

namespace dpc::studio {

void StudioBoard::setScene(std::string json) {
  auto text = std::make_shared<const std::string>(std::move(json));
  std::lock_guard<std::mutex> lock(mutex_);
  scene_ = std::move(text);
}

std::shared_ptr<const std::string> StudioBoard::scene() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return scene_;
}

void StudioBoard::setBake(std::string json) {
  auto text = std::make_shared<const std::string>(std::move(json));
  std::lock_guard<std::mutex> lock(mutex_);
  bake_ = std::move(text);
}

std::shared_ptr<const std::string> StudioBoard::bake() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bake_;
}

void StudioBoard::setAudio(std::shared_ptr<StudioAudio> audio) {
  std::lock_guard<std::mutex> lock(mutex_);
  audio_ = std::move(audio);
}

std::shared_ptr<StudioAudio> StudioBoard::audio() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return audio_;
}

namespace {

/// Appends `item` to `q`; returns the oldest entry when `q` then holds more than `kept` (the
/// caller frees it after releasing the lock), else null.
template <class T>
std::shared_ptr<const T> pushKept(std::deque<std::shared_ptr<const T>>& q,
                                  std::shared_ptr<const T> item, size_t kept) {
  q.push_back(std::move(item));
  if (q.size() <= kept) return nullptr;
  std::shared_ptr<const T> oldest = std::move(q.front());
  q.pop_front();
  return oldest;
}

/// The last entry of `q`, or null.
template <class T>
std::shared_ptr<const T> newest(const std::deque<std::shared_ptr<const T>>& q) {
  return q.empty() ? nullptr : q.back();
}

/// The entry of `q` whose frame is `frame`, or null.
template <class T>
std::shared_ptr<const T> ofFrame(const std::deque<std::shared_ptr<const T>>& q, uint64_t frame) {
  for (const auto& x : q)
    if (x->frame == frame) return x;
  return nullptr;
}

}  // namespace

void StudioBoard::publish(std::shared_ptr<const StudioFrame> frame) {
  std::shared_ptr<const StudioFrame> dropped;  // freed outside the lock
  std::lock_guard<std::mutex> lock(mutex_);
  dropped = pushKept(frames_, std::move(frame), kKeptFrames);
}

void StudioBoard::publishIr(std::shared_ptr<const StudioIr> ir) {
  std::shared_ptr<const StudioIr> dropped;  // freed outside the lock
  std::lock_guard<std::mutex> lock(mutex_);
  dropped = pushKept(irs_, std::move(ir), kKeptIrs);
}

void StudioBoard::wantIr() {
  std::lock_guard<std::mutex> lock(mutex_);
  irWanted_ = true;
}

bool StudioBoard::takeIrWanted() {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::exchange(irWanted_, false);
}

std::shared_ptr<const StudioIr> StudioBoard::latestIr() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return newest(irs_);
}

std::shared_ptr<const StudioIr> StudioBoard::findIr(uint64_t frame) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return ofFrame(irs_, frame);
}

std::shared_ptr<const StudioFrame> StudioBoard::latest() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return newest(frames_);
}

std::shared_ptr<const StudioFrame> StudioBoard::find(uint64_t frame) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return ofFrame(frames_, frame);
}

void StudioBoard::requestListener(const ListenerRequest& r) {
  std::lock_guard<std::mutex> lock(mutex_);
  requests_.listener = r;
}

void StudioBoard::requestSource(size_t index, const glm::vec3& position) {
  std::lock_guard<std::mutex> lock(mutex_);
  requests_.sources.emplace_back(index, position);
}

void StudioBoard::select(size_t source) {
  std::lock_guard<std::mutex> lock(mutex_);
  selected_ = source;
}

StudioRequests StudioBoard::take() {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::exchange(requests_, StudioRequests{});
}

size_t StudioBoard::selected() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return selected_;
}

}  // namespace dpc::studio
