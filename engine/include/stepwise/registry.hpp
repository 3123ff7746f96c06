#pragma once
/// \file registry.hpp
/// The entity registry: generational handles plus one sparse-set pool per
/// component type. Components are plain structs; systems iterate only the
/// entities that have every component they need (`each<A, B>`), walking the
/// smallest pool, so a scene pays only for the components it contains.

#include "stepwise/entity.hpp"

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <tuple>
#include <utility>
#include <type_traits>
#include <vector>

namespace stepwise {

namespace detail {

/// Dense small integers per component type, assigned on first use.
inline std::size_t nextComponentTypeId() {
    static std::size_t counter = 0;
    return counter++;
}
template <class T>
std::size_t componentTypeId() {
    static const std::size_t id = nextComponentTypeId();
    return id;
}

class PoolBase {
public:
    virtual ~PoolBase() = default;
    virtual bool contains(std::uint32_t index) const = 0;
    virtual void erase(std::uint32_t index) = 0;
    virtual std::size_t size() const = 0;
    virtual std::unique_ptr<PoolBase> clone() const = 0;
};

/// Sparse set: `sparse[entityIndex]` is the position in the dense arrays, or
/// kAbsent. Dense arrays stay packed (swap-remove), so iteration is linear.
template <class T>
class Pool final : public PoolBase {
public:
    static constexpr std::uint32_t kAbsent = 0xFFFFFFFFu;

    bool contains(std::uint32_t index) const override {
        return index < sparse_.size() && sparse_[index] != kAbsent;
    }
    T* find(std::uint32_t index) {
        return contains(index) ? &values_[sparse_[index]] : nullptr;
    }
    const T* find(std::uint32_t index) const {
        return contains(index) ? &values_[sparse_[index]] : nullptr;
    }
    T& set(std::uint32_t index, T value) {
        if (T* existing = find(index)) {
            *existing = std::move(value);
            return *existing;
        }
        if (index >= sparse_.size()) sparse_.resize(std::size_t(index) + 1, kAbsent);
        sparse_[index] = std::uint32_t(values_.size());
        owners_.push_back(index);
        values_.push_back(std::move(value));
        return values_.back();
    }
    void erase(std::uint32_t index) override {
        if (!contains(index)) return;
        const std::uint32_t slot = sparse_[index];
        const std::uint32_t last = std::uint32_t(values_.size() - 1);
        if (slot != last) {
            values_[slot] = std::move(values_[last]);
            owners_[slot] = owners_[last];
            sparse_[owners_[slot]] = slot;
        }
        values_.pop_back();
        owners_.pop_back();
        sparse_[index] = kAbsent;
    }
    std::size_t size() const override { return values_.size(); }
    std::unique_ptr<PoolBase> clone() const override { return std::make_unique<Pool>(*this); }
    /// Entity slot indices in dense order.
    const std::vector<std::uint32_t>& owners() const { return owners_; }

private:
    std::vector<std::uint32_t> sparse_;
    std::vector<std::uint32_t> owners_;
    std::vector<T> values_;
};

} // namespace detail

class Registry;

/// Told before a registry changes, so that an observer can keep what was
/// there: the editor's undo records the entities an edit touches without
/// copying or comparing the rest. Mutable access counts as a change (a
/// pointer from tryGet may be written through), so an observer may hear of
/// entities that end up unchanged.
class RegistryObserver {
public:
    /// Before `e`'s components change (e is alive).
    virtual void beforeEntityChange(const Registry& registry, Entity e) = 0;
    /// Before the slot table or the scene order changes (create, destroy,
    /// reorder, setSlots, assignment).
    virtual void beforeSlotsChange(const Registry& registry) = 0;

protected:
    ~RegistryObserver() = default;
};

/// Owns entities and their components. Copyable (deep copy), which the
/// editor's "reset to edited scene" relies on. An observer (setObserver)
/// belongs to the registry object, not its contents: assignment keeps it.
class Registry {
public:
    Registry() = default;
    Registry(const Registry& other) { copyFrom(other); }
    Registry& operator=(const Registry& other) {
        if (this == &other) return *this;
        beforeReplace();
        copyFrom(other);
        return *this;
    }
    Registry(Registry&& other) noexcept { moveFrom(std::move(other)); }
    Registry& operator=(Registry&& other) noexcept {
        if (this == &other) return *this;
        beforeReplace();
        moveFrom(std::move(other));
        return *this;
    }

    /// Tells `observer` (or nobody, for nullptr) of every change from now on.
    void setObserver(RegistryObserver* observer) { observer_ = observer; }

private:
    void copyFrom(const Registry& other) {
        generations_ = other.generations_;
        alive_ = other.alive_;
        freeList_ = other.freeList_;
        order_ = other.order_;
        pools_.clear();
        pools_.reserve(other.pools_.size());
        for (const auto& pool : other.pools_) pools_.push_back(pool ? pool->clone() : nullptr);
    }
    void moveFrom(Registry&& other) noexcept {
        generations_ = std::move(other.generations_);
        alive_ = std::move(other.alive_);
        freeList_ = std::move(other.freeList_);
        order_ = std::move(other.order_);
        pools_ = std::move(other.pools_);
    }
    /// Every entity and the slot table are about to be replaced.
    void beforeReplace() {
        if (!observer_) return;
        observer_->beforeSlotsChange(*this);
        for (const Entity e : order_) observer_->beforeEntityChange(*this, e);
    }
    void beforeChange(Entity e) {
        if (observer_ && alive(e)) observer_->beforeEntityChange(*this, e);
    }
    void beforeSlotsChange() {
        if (observer_) observer_->beforeSlotsChange(*this);
    }

public:
    /// Makes a new entity, appended to the scene order.
    Entity create() {
        beforeSlotsChange();
        std::uint32_t index;
        if (!freeList_.empty()) {
            index = freeList_.back();
            freeList_.pop_back();
        } else {
            index = std::uint32_t(generations_.size());
            generations_.push_back(0);
            alive_.push_back(false);
        }
        alive_[index] = true;
        const Entity e{index, generations_[index]};
        order_.push_back(e);
        return e;
    }

    /// Makes the entity with handle `e`, appended to the scene order: an
    /// entity of another registry made here under the same handle (a run's
    /// emitted copies written back to its scene). False, changing nothing,
    /// when that slot is alive or has been used by a later generation.
    bool createAt(Entity e) {
        if (e.isNull()) return false;
        if (e.index < generations_.size() && (alive_[e.index] || generations_[e.index] > e.generation)) return false;
        beforeSlotsChange();
        while (generations_.size() <= e.index) {
            freeList_.push_back(std::uint32_t(generations_.size()));
            generations_.push_back(0);
            alive_.push_back(false);
        }
        freeList_.erase(std::remove(freeList_.begin(), freeList_.end(), e.index), freeList_.end());
        generations_[e.index] = e.generation;
        alive_[e.index] = true;
        order_.push_back(e);
        return true;
    }

    /// True when `e` names a live entity (not destroyed, not stale).
    bool alive(Entity e) const {
        return e.index < generations_.size() && alive_[e.index] && generations_[e.index] == e.generation;
    }

    /// Destroys `e` and its components. A stale or null handle is a soft
    /// failure: returns false and changes nothing. O(entities) because the
    /// scene order is kept stable for saving.
    bool destroy(Entity e) {
        if (!alive(e)) return false;
        beforeChange(e);
        beforeSlotsChange();
        for (auto& pool : pools_)
            if (pool) pool->erase(e.index);
        alive_[e.index] = false;
        ++generations_[e.index];
        freeList_.push_back(e.index);
        order_.erase(std::find(order_.begin(), order_.end(), e));
        return true;
    }

    /// Live entities in scene order (creation order; the order they are saved in).
    const std::vector<Entity>& entities() const { return order_; }
    std::size_t size() const { return order_.size(); }
    void reserve(std::size_t n) { order_.reserve(n); generations_.reserve(n); alive_.reserve(n); }

    /// Moves `e` to position `position` in the scene order (clamped).
    void reorder(Entity e, std::size_t position) {
        auto it = std::find(order_.begin(), order_.end(), e);
        if (it == order_.end()) return;
        beforeSlotsChange();
        order_.erase(it);
        order_.insert(order_.begin() + std::ptrdiff_t(std::min(position, order_.size())), e);
    }

    /// Adds or replaces component T on `e`. `e` must be alive (asserted:
    /// a programmer error, not bad data).
    template <class T>
    T& emplace(Entity e, T value = T{}) {
        assert(alive(e));
        beforeChange(e);
        return pool<T>().set(e.index, std::move(value));
    }

    /// Pointer to e's T, or nullptr when e is stale or has no T.
    template <class T>
    T* tryGet(Entity e) {
        auto* p = findPool<T>();
        T* found = p && alive(e) ? p->find(e.index) : nullptr;
        if (found && observer_) observer_->beforeEntityChange(*this, e);
        return found;
    }
    template <class T>
    const T* tryGet(Entity e) const {
        auto* p = findPool<T>();
        return p && alive(e) ? p->find(e.index) : nullptr;
    }
    template <class T>
    bool has(Entity e) const { return tryGet<T>(e) != nullptr; }

    /// Removes e's T; returns whether there was one.
    template <class T>
    bool remove(Entity e) {
        auto* p = findPool<T>();
        if (!p || !alive(e) || !p->contains(e.index)) return false;
        beforeChange(e);
        p->erase(e.index);
        return true;
    }

    /// Number of entities that have T.
    template <class T>
    std::size_t count() const {
        auto* p = findPool<T>();
        return p ? p->size() : 0;
    }

    /// Calls fn(Entity, First&, Rest&...) for every entity that has all the
    /// listed components. Walks the smallest of the pools; order is that
    /// pool's dense order, which is deterministic for a given edit history.
    template <class First, class... Rest, class Fn>
    void each(Fn&& fn) {
        eachImpl<Registry, First, Rest...>(*this, std::forward<Fn>(fn));
    }
    template <class First, class... Rest, class Fn>
    void each(Fn&& fn) const {
        eachImpl<const Registry, First, Rest...>(*this, std::forward<Fn>(fn));
    }

    /// The slot table (generations, liveness, free list) and the scene
    /// order: with the components, all a Registry holds. The editor's undo
    /// keeps it for edits that create or destroy entities, so that undo and
    /// redo bring back the very same handles.
    struct Slots {
        std::vector<std::uint32_t> generations;
        std::vector<bool> alive;
        std::vector<std::uint32_t> freeList;
        std::vector<Entity> order;
        friend bool operator==(const Slots&, const Slots&) = default;
        std::size_t bytes() const {
            return 4 * (generations.capacity() + freeList.capacity()) + alive.capacity() / 8 +
                   sizeof(Entity) * order.capacity();
        }
    };
    Slots slots() const { return {generations_, alive_, freeList_, order_}; }
    /// Whether the slot table is `s` (slots() == s, without the copy).
    bool hasSlots(const Slots& s) const {
        return generations_ == s.generations && alive_ == s.alive && freeList_ == s.freeList && order_ == s.order;
    }
    /// Replaces the slot table. Remove the components of every entity that
    /// `s` does not keep alive first: pools are not touched here.
    void setSlots(Slots s) {
        beforeSlotsChange();
        generations_ = std::move(s.generations);
        alive_ = std::move(s.alive);
        freeList_ = std::move(s.freeList);
        order_ = std::move(s.order);
    }

    /// Slots in the slot table (every entity index is below it).
    std::size_t slotCount() const { return generations_.size(); }

    /// Handle currently in slot `index` if alive (used to turn dense pool
    /// owners back into handles).
    Entity handleAt(std::uint32_t index) const { return Entity{index, generations_[index]}; }

private:
    template <class T>
    detail::Pool<T>* findPool() const {
        const std::size_t id = detail::componentTypeId<T>();
        return id < pools_.size() ? static_cast<detail::Pool<T>*>(pools_[id].get()) : nullptr;
    }
    template <class T>
    detail::Pool<T>& pool() {
        const std::size_t id = detail::componentTypeId<T>();
        if (id >= pools_.size()) pools_.resize(id + 1);
        if (!pools_[id]) pools_[id] = std::make_unique<detail::Pool<T>>();
        return *static_cast<detail::Pool<T>*>(pools_[id].get());
    }

    template <class Self, class First, class... Rest, class Fn>
    static void eachImpl(Self& self, Fn&& fn) {
        const detail::PoolBase* smallest = self.template findPool<First>();
        if (!smallest) return;
        bool missing = false;
        ((self.template findPool<Rest>() ? void() : void(missing = true)), ...);
        if (missing) return;
        [[maybe_unused]] auto consider = [&](const detail::PoolBase* p) {
            if (p->size() < smallest->size()) smallest = p;
        };
        (consider(self.template findPool<Rest>()), ...);
        // Copy the owner list: fn may add components to other pools.
        std::vector<std::uint32_t> owners;
        if (smallest == self.template findPool<First>())
            owners = self.template findPool<First>()->owners();
        else
            owners = ownersOf<Self, Rest...>(self, smallest);
        for (std::uint32_t index : owners) {
            if (!(self.template findPool<First>()->contains(index) &&
                  (self.template findPool<Rest>()->contains(index) && ...)))
                continue;
            if constexpr (!std::is_const_v<Self>) self.beforeChange(self.handleAt(index));
            fn(self.handleAt(index), *self.template findPool<First>()->find(index),
               *self.template findPool<Rest>()->find(index)...);
        }
    }
    template <class Self, class... Ts>
    static std::vector<std::uint32_t> ownersOf([[maybe_unused]] Self& self, [[maybe_unused]] const detail::PoolBase* which) {
        std::vector<std::uint32_t> result;
        ((self.template findPool<Ts>() == which ? void(result = self.template findPool<Ts>()->owners()) : void()), ...);
        return result;
    }

    std::vector<std::uint32_t> generations_;
    std::vector<bool> alive_;
    std::vector<std::uint32_t> freeList_;
    std::vector<Entity> order_;
    std::vector<std::unique_ptr<detail::PoolBase>> pools_;
    RegistryObserver* observer_ = nullptr;
};

} // namespace stepwise
