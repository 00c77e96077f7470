! mufric for modern Fortran: ISO_C_BINDING interfaces to the C ABI (mufric.h). SI units throughout.
!   use mufric
!   type(c_ptr) :: client
!   if (mufric_connect('grpc://127.0.0.1:50051/gp', client, 'stream=1') /= MUFRIC_OK) print *, mufric_error()
!   status = mufric_evaluate(client, n, p, v, t, c_null_ptr, 0.95d0, mu, c_null_ptr, lo, hi, c_null_ptr)
module mufric
  use, intrinsic :: iso_c_binding
  implicit none
  private
  public :: mufric_connect, mufric_error, c_mufric_evaluate, c_mufric_close, c_mufric_evaluate_ex, c_mufric_box
  public :: c_mufric_patch_std, c_mufric_has_patch_scatter
  integer(c_int), parameter, public :: MUFRIC_OK = 0, MUFRIC_INVALID_ARGUMENT = 1, MUFRIC_FAILED = 2, &
                                       MUFRIC_PARTIAL = 3  ! answered, but not every point: see the statuses
  integer(c_int), parameter, public :: MUFRIC_POINT_OK = 0, MUFRIC_POINT_EXTRAPOLATED = 1, &
                                       MUFRIC_POINT_INVALID_INPUT = 2, MUFRIC_POINT_OUT_OF_BOX = 3

  ! One c_mufric_evaluate_ex call's counts over its points (mufric.h's mufric_counts).
  type, bind(C), public :: mufric_counts
    integer(c_size_t) :: extrapolated = 0, invalid = 0, out_of_box = 0, range_clipped = 0, fast_points = 0
  end type

  interface
    function c_mufric_open(uri, client) bind(C, name="mufric_open") result(status)
      import :: c_char, c_ptr, c_int
      character(kind=c_char), dimension(*), intent(in) :: uri
      type(c_ptr), intent(out) :: client
      integer(c_int) :: status
    end function
    function c_mufric_open_with_options(uri, options, client) bind(C, name="mufric_open_with_options") result(status)
      import :: c_char, c_ptr, c_int
      character(kind=c_char), dimension(*), intent(in) :: uri, options
      type(c_ptr), intent(out) :: client
      integer(c_int) :: status
    end function
    subroutine c_mufric_close(client) bind(C, name="mufric_close")
      import :: c_ptr
      type(c_ptr), value :: client
    end subroutine
    ! Inputs and outputs not used: pass c_null_ptr; otherwise c_loc of arrays of length n.
    function c_mufric_evaluate(client, n, contact_pressure, sliding_velocity, temperature, fibre_angle, &
                               ci_level, mu, std, lo, hi, status) bind(C, name="mufric_evaluate") result(code)
      import :: c_ptr, c_size_t, c_double, c_int
      type(c_ptr), value :: client
      integer(c_size_t), value :: n
      type(c_ptr), value :: contact_pressure, sliding_velocity, temperature, fibre_angle
      real(c_double), value :: ci_level
      type(c_ptr), value :: mu, std, lo, hi, status
      integer(c_int) :: code
    end function
    ! c_mufric_evaluate and two more outputs (c_null_ptr if not wanted): outside, c_loc of an
    ! integer(c_int) array of length n, bit 2k (below) and 2k+1 (above the box) for input k = 0..3 in
    ! argument order; counts, c_loc of a type(mufric_counts). Unanswered points' message: mufric_error().
    function c_mufric_evaluate_ex(client, n, contact_pressure, sliding_velocity, temperature, fibre_angle, &
                                  ci_level, mu, std, lo, hi, status, outside, counts) &
        bind(C, name="mufric_evaluate_ex") result(code)
      import :: c_ptr, c_size_t, c_double, c_int
      type(c_ptr), value :: client
      integer(c_size_t), value :: n
      type(c_ptr), value :: contact_pressure, sliding_velocity, temperature, fibre_angle
      real(c_double), value :: ci_level
      type(c_ptr), value :: mu, std, lo, hi, status, outside, counts
      integer(c_int) :: code
    end function
    ! The model's training box in argument order (pressure, velocity, temperature, fibre angle), SI;
    ! used(k) = 1 for an input the model takes.
    function c_mufric_box(client, used, lo, hi) bind(C, name="mufric_box") result(code)
      import :: c_ptr, c_double, c_int
      type(c_ptr), value :: client
      integer(c_int), intent(out) :: used(4)
      real(c_double), intent(out) :: lo(4), hi(4)
      integer(c_int) :: code
    end function
    ! The patch scatter: per point, the micro-model's per-draw standard deviation of mu about the mean
    ! (c_loc of an array of length n); MUFRIC_INVALID_ARGUMENT when c_mufric_has_patch_scatter is 0.
    function c_mufric_patch_std(client, n, contact_pressure, sliding_velocity, temperature, fibre_angle, &
                                patch_std, status) bind(C, name="mufric_patch_std") result(code)
      import :: c_ptr, c_size_t, c_int
      type(c_ptr), value :: client
      integer(c_size_t), value :: n
      type(c_ptr), value :: contact_pressure, sliding_velocity, temperature, fibre_angle
      type(c_ptr), value :: patch_std, status
      integer(c_int) :: code
    end function
    function c_mufric_has_patch_scatter(client) bind(C, name="mufric_has_patch_scatter") result(has)
      import :: c_ptr, c_int
      type(c_ptr), value :: client
      integer(c_int) :: has
    end function
    function c_mufric_last_error() bind(C, name="mufric_last_error") result(message)
      import :: c_ptr
      type(c_ptr) :: message
    end function
  end interface

contains

  ! Opens a model by URI (Fortran string, trailing blanks ignored). options: as mufric_open_with_options
  ! in mufric.h, e.g. 'stream=1, deadline=2, token=abc'.
  function mufric_connect(uri, client, options) result(status)
    character(len=*), intent(in) :: uri
    type(c_ptr), intent(out) :: client
    character(len=*), intent(in), optional :: options
    integer(c_int) :: status
    if (present(options)) then
      status = c_mufric_open_with_options(trim(uri) // c_null_char, trim(options) // c_null_char, client)
    else
      status = c_mufric_open(trim(uri) // c_null_char, client)
    end if
  end function

  ! The last error message of this thread.
  function mufric_error() result(message)
    character(len=:), allocatable :: message
    character(kind=c_char), pointer :: chars(:)
    integer :: length
    type(c_ptr) :: raw
    raw = c_mufric_last_error()
    call c_f_pointer(raw, chars, [4096])
    length = 0
    do while (length < 4096)
      if (chars(length + 1) == c_null_char) exit
      length = length + 1
    end do
    allocate(character(len=length) :: message)
    message = transfer(chars(1:length), message)
  end function

end module mufric
