// A bump allocator for what a shading point prepares: objects made here live until reset().
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace hairis {

/// Memory for short-lived objects of one thread (pbrt-v4's ScratchBuffer idea). Objects must
/// be trivially destructible: reset() releases them without calling destructors.
class ScratchBuffer {
  public:
    explicit ScratchBuffer(std::size_t bytes = 4096) : block_(new std::byte[bytes]), size_(bytes) {}
    ScratchBuffer(const ScratchBuffer &) = delete;
    ScratchBuffer &operator=(const ScratchBuffer &) = delete;

    /// Constructs a T here.
    template <typename T, typename... Args>
    T &make(Args &&...args) {
        static_assert(std::is_trivially_destructible_v<T>, "scratch objects are never destroyed");
        return *new (allocate(sizeof(T), alignof(T))) T(std::forward<Args>(args)...);
    }

    /// Constructs a T whose only non-trivial part is a virtual destructor (a model class whose
    /// members are all trivially destructible): reset() skips its destructor, which does nothing.
    template <typename T, typename... Args>
    T &make_polymorphic(Args &&...args) {
        static_assert(std::has_virtual_destructor_v<T>, "use make() for other types");
        return *new (allocate(sizeof(T), alignof(T))) T(std::forward<Args>(args)...);
    }

    /// Releases everything made since the last reset; keeps the current (largest) block.
    void reset() {
        full_.clear();
        used_ = 0;
    }

  private:
    // The first address at or after `used` in the block that is a multiple of align.
    std::size_t aligned(std::size_t used, std::size_t align) const {
        const std::uintptr_t at = reinterpret_cast<std::uintptr_t>(block_.get()) + used;
        return used + ((align - at % align) % align);
    }
    void *allocate(std::size_t size, std::size_t align) {
        std::size_t start = aligned(used_, align);
        if (start + size > size_) {
            const std::size_t previous = size_;
            full_.emplace_back(std::move(block_), previous);
            size_ = std::max(2 * previous, size + align);
            block_.reset(new std::byte[size_]);
            start = aligned(0, align);
        }
        used_ = start + size;
        return block_.get() + start;
    }

    std::unique_ptr<std::byte[]> block_;
    std::size_t size_ = 0, used_ = 0;
    std::vector<std::pair<std::unique_ptr<std::byte[]>, std::size_t>> full_;  // until reset()
};

}  // namespace hairis
