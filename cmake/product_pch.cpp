// The translation unit that tofguard_pch's precompiled header is built with
// (cmake/ProductPch.cmake); the product's libraries and executables reuse
// the header, none links this.
