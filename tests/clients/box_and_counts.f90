! The Fortran module's view of box_and_counts.c: c_mufric_box and the counts of c_mufric_evaluate_ex
! for a block with a point inside, one below and one above the box in each input and a negative
! pressure, under the model's default (clamp) policy and under refuse with fill=-1. Usage: URI
program box_and_counts
  use, intrinsic :: iso_c_binding
  use mufric
  use client_checks
  implicit none
  integer, parameter :: n = 8
  real(c_double), target :: p(n), v(n), t(n), mu(n), lo_ci(n), hi_ci(n)
  integer(c_int), target :: status(n), outside(n)
  type(mufric_counts), target :: counts
  integer(c_int) :: used(4)
  real(c_double) :: lo(4), hi(4)
  type(c_ptr) :: client
  character(len=1024) :: uri
  character(len=*), parameter :: options(2) = [character(len=32) :: 'extrapolation=clamp', &
                                                                     'extrapolation=refuse, fill=-1']
  integer :: k, policy

  call get_command_argument(1, uri)
  do policy = 1, 2
    write (check_context, '(a, i0, a)') ' (policy ', policy, ')'
    if (mufric_connect(uri, client, trim(options(policy))) /= MUFRIC_OK) then
      write (0, *) 'mufric_connect: ', mufric_error()
      stop 1
    end if
    if (c_mufric_box(client, used, lo, hi) /= MUFRIC_OK) then
      write (0, *) 'mufric_box: ', mufric_error()
      stop 1
    end if
    call check(all(used == [1, 1, 1, 0]), 'used inputs')
    call check(all(lo(1:3) < hi(1:3)) .and. lo(4) == 0 .and. hi(4) == 0, 'box bounds')

    p = 0.5d0 * (lo(1) + hi(1))
    v = 0.5d0 * (lo(2) + hi(2))
    t = 0.5d0 * (lo(3) + hi(3))
    p(2) = lo(1) * 0.9d0
    p(3) = hi(1) * 1.1d0
    v(4) = lo(2) * 0.9d0
    v(5) = hi(2) * 1.1d0
    t(6) = lo(3) * 0.9d0
    t(7) = hi(3) * 1.1d0
    p(8) = -5d6
    if (c_mufric_evaluate_ex(client, int(n, c_size_t), c_loc(p), c_loc(v), c_loc(t), c_null_ptr, 0.95d0, &
                             c_loc(mu), c_null_ptr, c_loc(lo_ci), c_loc(hi_ci), c_loc(status), c_loc(outside), &
                             c_loc(counts)) /= MUFRIC_PARTIAL) then
      write (0, *) 'mufric_evaluate_ex: ', mufric_error()
      stop 1
    end if
    call check(counts%invalid == count(status == MUFRIC_POINT_INVALID_INPUT) .and. counts%invalid == 1, 'invalid')
    call check(counts%extrapolated == count(status == MUFRIC_POINT_EXTRAPOLATED), 'extrapolated')
    call check(counts%out_of_box == count(status == MUFRIC_POINT_OUT_OF_BOX), 'out_of_box')
    call check(counts%extrapolated + counts%out_of_box == 6, 'six points outside the box')
    do k = 2, 7
      ! Point k lies below (even k) or above (odd k) input (k - 2) / 2: bit 2 * input (+ 1 above).
      call check(outside(k) == ishft(1, k - 2), 'outside flags')
    end do
    call check(outside(1) == 0 .and. outside(8) == 1, 'inside: no flag; a negative pressure: below')
    if (policy == 2) then
      call check(all(mu(2:8) == -1d0) .and. all(lo_ci(2:8) == -1d0) .and. all(hi_ci(2:8) == -1d0), 'fill=-1')
      call check(index(mufric_error(), 'point 1 OUT_OF_BOX') == 1, 'message: ' // mufric_error())
    else
      call check(index(mufric_error(), 'point 7 INVALID_INPUT') == 1, 'message: ' // mufric_error())
    end if
    call c_mufric_close(client)
  end do
  if (failures > 0) stop 1
  print '(a)', 'box_and_counts (Fortran): every check passed'

end program
