// VoxelArray: a volume's samples, kept in the file's type (conventions section 1).
//
// The bytes are held as the ScalarType the data came in (u8 .. u32, i8 .. i32, f32, f64), so a volume
// takes its file's size in memory, not 8 bytes per voxel. Every read converts to double, which is
// exact for all eight types, so what the renderer computes does not depend on the storage.
//
// Two ways to read:
//   - by value: size(), operator[](i) and begin()/end() give doubles (one switch on the type per
//     read: for set-up passes, messages and tests, not for the per-sample paths);
//   - typed: data<T>() or visit(f), which calls f(const T*) with the type's own pointer once, so hot
//     loops are instantiated per type and dispatch once per sample, packet or pass.
// Building: VoxelArray(type, count) or allocate(type, count, zero) (the readers fill the bytes in
// place), set(i, x) (x must be exactly representable in the type: an Error otherwise) or typed writes
// through data<T>(). For f64 storage (procedural fields, resampling, gradient caches, tests) it also
// behaves like the std::vector<double> it replaced: assignment from a vector or braced list,
// push_back, assign, resize, pop_back, back.
//
// The buffer is 64-byte aligned and has kPadBytes of zeros before and after the samples, so a SIMD
// gather of a 32-bit word around an 8- or 16-bit sample stays inside the allocation. A buffer of at
// least kHugeBufferBytes is aligned to 2 MiB and advised onto transparent huge pages before its first
// touch (madvise MADV_HUGEPAGE, where the system has it: Debian's default THP mode is "madvise", so
// without the advice a 64 MiB volume is 16,384 pages of 4 KiB and the ray marcher's voxel reads miss
// the TLB). On the EPYC they did not help (docs/performance.md, "What did not help").
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace volref {

enum class ScalarType { U8, I8, U16, I16, U32, I32, F32, F64 };

// "u8", "i16", "f32", ... (the names used in scene files, sidecars and messages).
const char* scalar_type_name(ScalarType t);
// Size of one value of the type in bytes.
std::size_t scalar_type_size(ScalarType t);
// True for the integer types.
bool scalar_type_is_integer(ScalarType t);
// [lowest, highest] representable value of an integer type (used as the default normalisation window).
std::array<double, 2> scalar_type_range(ScalarType t);

// The C++ type of each ScalarType, and back.
template <ScalarType S> struct ScalarCpp;
template <> struct ScalarCpp<ScalarType::U8> { using type = std::uint8_t; };
template <> struct ScalarCpp<ScalarType::I8> { using type = std::int8_t; };
template <> struct ScalarCpp<ScalarType::U16> { using type = std::uint16_t; };
template <> struct ScalarCpp<ScalarType::I16> { using type = std::int16_t; };
template <> struct ScalarCpp<ScalarType::U32> { using type = std::uint32_t; };
template <> struct ScalarCpp<ScalarType::I32> { using type = std::int32_t; };
template <> struct ScalarCpp<ScalarType::F32> { using type = float; };
template <> struct ScalarCpp<ScalarType::F64> { using type = double; };

template <class T> constexpr ScalarType scalar_type_of() {
    if constexpr (std::is_same_v<T, std::uint8_t>) return ScalarType::U8;
    else if constexpr (std::is_same_v<T, std::int8_t>) return ScalarType::I8;
    else if constexpr (std::is_same_v<T, std::uint16_t>) return ScalarType::U16;
    else if constexpr (std::is_same_v<T, std::int16_t>) return ScalarType::I16;
    else if constexpr (std::is_same_v<T, std::uint32_t>) return ScalarType::U32;
    else if constexpr (std::is_same_v<T, std::int32_t>) return ScalarType::I32;
    else if constexpr (std::is_same_v<T, float>) return ScalarType::F32;
    else {
        static_assert(std::is_same_v<T, double>, "not a voxel type");
        return ScalarType::F64;
    }
}

// Calls f(T{}) (a value of the C++ type of `type`, to deduce T from): the one switch of a typed pass.
template <class F> decltype(auto) dispatch_scalar_type(ScalarType type, F&& f) {
    switch (type) {
        case ScalarType::U8: return f(std::uint8_t{});
        case ScalarType::I8: return f(std::int8_t{});
        case ScalarType::U16: return f(std::uint16_t{});
        case ScalarType::I16: return f(std::int16_t{});
        case ScalarType::U32: return f(std::uint32_t{});
        case ScalarType::I32: return f(std::int32_t{});
        case ScalarType::F32: return f(float{});
        case ScalarType::F64: break;
    }
    return f(double{});
}

// True when x converts to T and back unchanged (NaN and +-infinity count as exact for f32 and f64).
template <class T> bool exactly_representable(double x) {
    if constexpr (std::is_floating_point_v<T>) {
        if (!std::isfinite(x)) return true;
        if constexpr (std::is_same_v<T, float>)
            if (std::fabs(x) > double(std::numeric_limits<float>::max())) return false;
        return double(T(x)) == x;
    } else {
        return x >= double(std::numeric_limits<T>::lowest()) && x <= double(std::numeric_limits<T>::max()) &&
               std::floor(x) == x;
    }
}

class VoxelArray {
public:
    static constexpr std::size_t kAlignment = 64;
    static constexpr std::size_t kPadBytes = 64;
    static constexpr std::size_t kHugePage = std::size_t(1) << 21;        // 2 MiB
    static constexpr std::size_t kHugeBufferBytes = std::size_t(4) << 20;  // 4 MiB: below it, 4 KiB pages

    VoxelArray() = default;
    VoxelArray(ScalarType type, std::size_t count) { allocate(type, count, true); }
    VoxelArray(std::initializer_list<double> v) { assign_doubles(v.begin(), v.size()); }
    VoxelArray(const std::vector<double>& v) { assign_doubles(v.data(), v.size()); }  // NOLINT: implicit, as before
    VoxelArray(const VoxelArray& o) { copy_from(o); }
    VoxelArray(VoxelArray&& o) noexcept { swap(o); }
    VoxelArray& operator=(const VoxelArray& o) {
        if (this != &o) {
            VoxelArray tmp(o);
            swap(tmp);
        }
        return *this;
    }
    VoxelArray& operator=(VoxelArray&& o) noexcept {
        VoxelArray tmp(std::move(o));
        swap(tmp);
        return *this;
    }
    VoxelArray& operator=(std::initializer_list<double> v) {
        assign_doubles(v.begin(), v.size());
        return *this;
    }
    VoxelArray& operator=(const std::vector<double>& v) {
        assign_doubles(v.data(), v.size());
        return *this;
    }
    ~VoxelArray() { release(); }

    void swap(VoxelArray& o) noexcept {
        std::swap(base_, o.base_);
        std::swap(data_, o.data_);
        std::swap(type_, o.type_);
        std::swap(size_, o.size_);
        std::swap(capacity_, o.capacity_);
    }

    // `count` samples of `type`; zero-filled when `zero`, otherwise left for the caller to fill (the
    // readers). The previous contents are released first.
    void allocate(ScalarType type, std::size_t count, bool zero = true) {
        release();
        reserve_bytes(type, count);
        size_ = count;
        if (zero && count > 0) std::memset(data_, 0, count * scalar_type_size(type));
    }

    ScalarType type() const { return type_; }
    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    // The samples' bytes (size() x the type's size): what the volume holds in memory.
    std::size_t bytes() const { return size_ * scalar_type_size(type_); }

    double operator[](std::size_t i) const {
        switch (type_) {
            case ScalarType::U8: return double(static_cast<const std::uint8_t*>(data_)[i]);
            case ScalarType::I8: return double(static_cast<const std::int8_t*>(data_)[i]);
            case ScalarType::U16: return double(static_cast<const std::uint16_t*>(data_)[i]);
            case ScalarType::I16: return double(static_cast<const std::int16_t*>(data_)[i]);
            case ScalarType::U32: return double(static_cast<const std::uint32_t*>(data_)[i]);
            case ScalarType::I32: return double(static_cast<const std::int32_t*>(data_)[i]);
            case ScalarType::F32: return double(static_cast<const float*>(data_)[i]);
            case ScalarType::F64: break;
        }
        return static_cast<const double*>(data_)[i];
    }

    // A writable element of a non-const array: reads as double, assigning a double calls set().
    class Reference {
    public:
        Reference(VoxelArray& a, std::size_t i) : a_(&a), i_(i) {}
        operator double() const { return std::as_const(*a_)[i_]; }  // NOLINT: implicit by design
        Reference& operator=(double x) {
            a_->set(i_, x);
            return *this;
        }
        Reference& operator=(const Reference& r) { return *this = double(r); }

    private:
        VoxelArray* a_;
        std::size_t i_;
    };
    Reference operator[](std::size_t i) { return Reference(*this, i); }

    // Stores x at i; x must be exactly representable in the storage type (std::invalid_argument).
    void set(std::size_t i, double x) {
        dispatch_scalar_type(type_, [&](auto tag) {
            using T = decltype(tag);
            if (!exactly_representable<T>(x))
                throw std::invalid_argument(std::string("voxel value ") + std::to_string(x) +
                                            " is not exactly representable as " + scalar_type_name(type_));
            static_cast<T*>(data_)[i] = T(x);
        });
    }

    template <class T> const T* data() const {
        check_type<T>();
        return static_cast<const T*>(data_);
    }
    template <class T> T* data() {
        check_type<T>();
        return static_cast<T*>(data_);
    }
    const void* raw() const { return data_; }
    void* raw() { return data_; }

    // f(const T*) with the storage's own type and pointer.
    template <class F> decltype(auto) visit(F&& f) const {
        return dispatch_scalar_type(type_, [&](auto tag) -> decltype(auto) {
            using T = decltype(tag);
            return f(static_cast<const T*>(data_));
        });
    }
    template <class F> decltype(auto) visit_mutable(F&& f) {
        return dispatch_scalar_type(type_, [&](auto tag) -> decltype(auto) {
            using T = decltype(tag);
            return f(static_cast<T*>(data_));
        });
    }

    // The values as doubles (a copy: 8 bytes per voxel).
    std::vector<double> to_vector() const {
        std::vector<double> out(size_);
        visit([&](const auto* p) { std::copy(p, p + size_, out.begin()); });
        return out;
    }

    // ---- std::vector<double>-like building, f64 storage only (an empty array is f64) ----
    void push_back(double x) {
        require_f64("push_back");
        if (size_ == capacity_) grow(std::max<std::size_t>(16, 2 * capacity_));
        static_cast<double*>(data_)[size_++] = x;
    }
    void pop_back() { --size_; }
    double back() const { return (*this)[size_ - 1]; }
    double front() const { return (*this)[0]; }
    void reserve(std::size_t n) {
        require_f64("reserve");
        if (n > capacity_) grow(n);
    }
    void assign(std::size_t n, double x) {
        allocate(ScalarType::F64, n, false);
        std::fill_n(static_cast<double*>(data_), n, x);
    }
    void resize(std::size_t n) {
        require_f64("resize");
        if (n > capacity_) grow(n);
        if (n > size_) std::fill(static_cast<double*>(data_) + size_, static_cast<double*>(data_) + n, 0.0);
        size_ = n;
    }
    void clear() { size_ = 0; }

    // ---- iteration as doubles ----
    class const_iterator {
    public:
        using iterator_category = std::random_access_iterator_tag;
        using value_type = double;
        using difference_type = std::ptrdiff_t;
        using pointer = void;
        using reference = double;
        const_iterator() = default;
        const_iterator(const VoxelArray* a, std::size_t i) : a_(a), i_(i) {}
        double operator*() const { return (*a_)[i_]; }
        double operator[](difference_type n) const { return (*a_)[std::size_t(difference_type(i_) + n)]; }
        const_iterator& operator++() { ++i_; return *this; }
        const_iterator operator++(int) { auto t = *this; ++i_; return t; }
        const_iterator& operator--() { --i_; return *this; }
        const_iterator operator--(int) { auto t = *this; --i_; return t; }
        const_iterator& operator+=(difference_type n) { i_ = std::size_t(difference_type(i_) + n); return *this; }
        const_iterator& operator-=(difference_type n) { i_ = std::size_t(difference_type(i_) - n); return *this; }
        const_iterator operator+(difference_type n) const { auto t = *this; return t += n; }
        const_iterator operator-(difference_type n) const { auto t = *this; return t -= n; }
        difference_type operator-(const const_iterator& o) const { return difference_type(i_) - difference_type(o.i_); }
        bool operator==(const const_iterator& o) const { return i_ == o.i_; }
        bool operator!=(const const_iterator& o) const { return i_ != o.i_; }
        bool operator<(const const_iterator& o) const { return i_ < o.i_; }

    private:
        const VoxelArray* a_ = nullptr;
        std::size_t i_ = 0;
    };
    using iterator = const_iterator;
    using value_type = double;
    using size_type = std::size_t;
    using reference = double;
    using const_reference = double;
    const_iterator begin() const { return {this, 0}; }
    const_iterator end() const { return {this, size_}; }

    // Equal values (as doubles, NaN unequal to everything), whatever the storage types.
    friend bool operator==(const VoxelArray& a, const VoxelArray& b) {
        if (a.size_ != b.size_) return false;
        for (std::size_t i = 0; i < a.size_; ++i)
            if (!(a[i] == b[i])) return false;
        return true;
    }
    friend bool operator==(const VoxelArray& a, const std::vector<double>& b) {
        if (a.size_ != b.size()) return false;
        for (std::size_t i = 0; i < b.size(); ++i)
            if (!(a[i] == b[i])) return false;
        return true;
    }

private:
    template <class T> void check_type() const {
        if (scalar_type_of<T>() != type_)
            throw std::logic_error(std::string("VoxelArray: data<") + scalar_type_name(scalar_type_of<T>()) +
                                   "> of " + scalar_type_name(type_) + " storage");
    }
    void require_f64(const char* what) const {
        if (type_ != ScalarType::F64)
            throw std::logic_error(std::string("VoxelArray::") + what + " on " + scalar_type_name(type_) + " storage");
    }
    // A fresh buffer for `count` values of `type` (contents undefined), old one released.
    void reserve_bytes(ScalarType type, std::size_t count) {
        const std::size_t bytes = count * scalar_type_size(type);
        const std::size_t total = bytes + 2 * kPadBytes, alignment = alignment_of(total);
        base_ = static_cast<std::byte*>(::operator new(total, std::align_val_t(alignment)));
        if (alignment == kHugePage) advise_huge_pages(base_, total);
        std::memset(base_, 0, kPadBytes);
        std::memset(base_ + kPadBytes + bytes, 0, kPadBytes);
        data_ = base_ + kPadBytes;
        type_ = type;
        capacity_ = count;
    }
    void grow(std::size_t n) {
        VoxelArray bigger;
        bigger.reserve_bytes(ScalarType::F64, n);
        if (size_ > 0) std::memcpy(bigger.data_, data_, size_ * sizeof(double));
        bigger.size_ = size_;
        swap(bigger);
    }
    void assign_doubles(const double* p, std::size_t n) {
        VoxelArray tmp;
        tmp.allocate(ScalarType::F64, n, false);
        if (n > 0) std::memcpy(tmp.data_, p, n * sizeof(double));
        swap(tmp);
    }
    void copy_from(const VoxelArray& o) {
        allocate(o.type_, o.size_, false);
        if (o.size_ > 0) std::memcpy(data_, o.data_, o.bytes());
    }
    void release() {
        if (base_) ::operator delete(base_, std::align_val_t(alignment_of(capacity_ * scalar_type_size(type_) + 2 * kPadBytes)));
        base_ = nullptr;
        data_ = nullptr;
        size_ = capacity_ = 0;
        type_ = ScalarType::F64;
    }

    // The alignment of a buffer of `total` bytes (samples and pads: capacity_ x the type's size + 2 kPadBytes).
    static constexpr std::size_t alignment_of(std::size_t total) { return total >= kHugeBufferBytes ? kHugePage : kAlignment; }
    // madvise(MADV_HUGEPAGE) on the whole 2 MiB pages of [p, p + bytes) (Volume.cpp; nothing where the
    // system lacks it or refuses: the advice changes no value).
    static void advise_huge_pages(void* p, std::size_t bytes);

    std::byte* base_ = nullptr;
    void* data_ = nullptr;
    ScalarType type_ = ScalarType::F64;
    std::size_t size_ = 0;
    std::size_t capacity_ = 0;
};

// The number of NaN and +-infinity values (0 for the integer types), one typed pass: a value is
// non-finite when its exponent bits are all ones (an integer test the compiler vectorises).
inline std::size_t count_non_finite(const VoxelArray& a) {
    return a.visit([&](const auto* p) -> std::size_t {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(p)>>;
        if constexpr (std::is_integral_v<T>) {
            return 0;
        } else {
            using Bits = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
            constexpr Bits kExponent = sizeof(T) == 4 ? Bits(0x7f800000u) : Bits(0x7ff0000000000000ull);
            std::size_t count = 0;
            for (std::size_t i = 0; i < a.size(); ++i) {
                Bits b;
                std::memcpy(&b, p + i, sizeof(T));
                count += (b & kExponent) == kExponent;
            }
            return count;
        }
    });
}

// True when no value is NaN or +-infinity (always, for the integer types).
inline bool all_finite(const VoxelArray& a) { return count_non_finite(a) == 0; }

}  // namespace volref
